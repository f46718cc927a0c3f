#include "hapsim/render/teleop_scene.h"

#include <algorithm>
#include <cmath>
#include <utility>

namespace hapsim {

namespace {

/// A box with half extents `half` centred at the origin, four vertices per face so the vertex
/// normals are the face normals (flat-shaded faces, sharp edges).
TriangleMesh flat_box(const Vec3& half) {
  TriangleMesh m;
  for (int a = 0; a < 3; ++a) {
    const int u = (a + 1) % 3;
    const int v = (a + 2) % 3;
    for (const double s : {-1.0, 1.0}) {
      const auto base = static_cast<std::uint32_t>(m.vertices.size());
      for (const auto& [su, sv] : {std::pair{-1.0, -1.0}, {1.0, -1.0}, {1.0, 1.0}, {-1.0, 1.0}}) {
        Vec3 p = Vec3::Zero();
        p[a] = s * half[a];
        p[u] = su * half[u];
        p[v] = sv * half[v];
        m.vertices.push_back(p);
      }
      // e_u × e_v = e_a: counter-clockwise seen from +e_a; reversed on the −e_a face.
      if (s > 0.0) {
        m.triangles.push_back({base, base + 1, base + 2});
        m.triangles.push_back({base, base + 2, base + 3});
      } else {
        m.triangles.push_back({base, base + 2, base + 1});
        m.triangles.push_back({base, base + 3, base + 2});
      }
    }
  }
  m.compute_vertex_normals();
  return m;
}

/// A box of square cross-section (half side `half_width_m`) from the origin to `d`.
TriangleMesh link_box(const Vec3& d, double half_width_m) {
  const double length = d.norm();
  TriangleMesh m = flat_box(Vec3(half_width_m, half_width_m, 0.5 * length));
  const Quat R = Quat::FromTwoVectors(Vec3::UnitZ(), d / length);
  m.transform(Iso3(Eigen::Translation3d(0.5 * d)) * Iso3(R));
  return m;
}

/// The point `p_master` (master base frame) where the master is drawn.
Vec3 master_point_world(const Vec3& origin_world, double scale, const Vec3& p_master) {
  return origin_world + scale * p_master;
}

}  // namespace

TeleopScene::TeleopScene(const World& world, TeleopSceneOptions options)
    : world_(world), options_(std::move(options)), scratch_(make_teleop_snapshot(world)) {
  build_slave();
  build_gripper();
  // The sheet, placed by the environment; its x, y never change, z follows the heights.
  const VirtualSheet& sheet = *world_.sheet(world_.description().teleop->sheet_body);
  sheet_ = scene_.add_mesh(sheet.mesh(), options_.colours.sheet,
                           world_.description().teleop->environment.X_world_sheet);
  scene_.mesh(sheet_).name = "sheet";
  sheet_positions_ = sheet.mesh().vertices;
  uploaded_heights_m_.assign(sheet.surface_heights().begin(), sheet.surface_heights().end());
  frames_.resize(static_cast<std::size_t>(world_.rig()->slave->chain().dof()));
  scene_.style.line_width_px = 2.0f;

  const bool show_master = options_.show_master;
  options_.show_master = false;  // placed below, beside what the rest occupies
  update(scratch_);
  options_.show_master = show_master;
  Box3 bounds = scene_.bounds_world();  // slave at its start, gripper, ball, sheet
  const BallEnvironmentOptions& env = world_.description().teleop->environment;
  const double floor_z = env.has_floor ? env.floor_z_m : bounds.min().z();
  bounds.extend(Vec3(bounds.min().x(), bounds.min().y(), floor_z));
  // The master stands on the floor beside the slave's −y side, clear of the ball.
  const MasterArmGeometry& g = world_.model().master()->geometry();
  const double master_reach =
      options_.master_display_scale * (g.upper_arm_m + g.forearm_m + g.finger_m);
  master_origin_world_ = Vec3(bounds.center().x(), bounds.min().y() - 0.6 * master_reach, floor_z);
  if (options_.show_master) {
    pose_from(scratch_);
    for (const RenderSegment& seg : scene_.segments) {
      bounds.extend(seg.a_world);
      bounds.extend(seg.b_world);
    }
  }
  rest_bounds_world_ = bounds;
  // A floor under everything, a little wider, 5 cm checks.
  scene_.floor.visible = env.has_floor;
  scene_.floor.height_m = floor_z;
  scene_.floor.centre_x_m = bounds.center().x();
  scene_.floor.centre_y_m = bounds.center().y();
  scene_.floor.half_extent_m = 0.6 * bounds.sizes().head<2>().maxCoeff() + 0.1;
  scene_.floor.cell_m = 0.05;
}

void TeleopScene::build_slave() {
  const SerialChain& chain = world_.rig()->slave->chain();
  if (!chain.link_geometry().empty()) {
    for (const ChainLinkGeometry& g : chain.link_geometry()) {
      if (g.mesh.empty()) {
        continue;
      }
      Link link;
      link.mesh = scene_.add_mesh(g.mesh, options_.colours.robot);
      link.frame = g.frame;
      link.X_frame_mesh = g.X_frame_mesh;
      scene_.mesh(link.mesh).name = g.link;
      links_.push_back(link);
      link_mesh_ids_.push_back(link.mesh);
    }
    return;
  }
  // No meshes: a box per link from one joint origin to the next (the origin of joint k's frame is
  // fixed in frame k−1 for a revolute joint; a prismatic joint's link is drawn at q = 0), the
  // base link thickest, tapering towards the tip.
  const int n = chain.dof();
  std::vector<Vec3> offsets;  // offsets[k]: origin of frame k (k = n: the tip) in frame k − 1
  double total_m = 0.0;
  for (int k = 0; k <= n; ++k) {
    offsets.push_back(k < n
                          ? chain.joints()[static_cast<std::size_t>(k)].X_parent_joint.translation()
                          : chain.X_last_tip().translation());
    total_m += offsets.back().norm();
  }
  const double scale = std::max(total_m, 0.1);
  auto half_width = [&](int k) {
    const double u = n > 0 ? static_cast<double>(k) / static_cast<double>(n) : 0.0;
    return scale * (0.035 - 0.015 * u);
  };
  for (int k = 0; k <= n; ++k) {
    const Vec3& d = offsets[static_cast<std::size_t>(k)];
    if (d.norm() < 1e-6) {
      continue;
    }
    Link link;
    link.mesh = scene_.add_mesh(link_box(d, half_width(k)), options_.colours.robot);
    link.frame = k - 1;
    scene_.mesh(link.mesh).name =
        k == 0 ? chain.base_link() : chain.joints()[static_cast<std::size_t>(k - 1)].child_link;
    links_.push_back(link);
    link_mesh_ids_.push_back(link.mesh);
  }
  for (int k = 0; k < n; ++k) {
    joint_radius_m_.push_back(1.3 * std::max(half_width(k), half_width(k + 1)));
  }
}

void TeleopScene::build_gripper() {
  const ParallelGripperParams& p = world_.description().teleop->gripper;
  const double max_width = world_.description().teleop->follower.gripper_max_width_m;
  // A palm across the pads' travel just above them, and a stem from the flange down to it.
  const double palm_half_z = 0.25 * p.pad_half_m.z();
  const double palm_z = p.pad_depth_m - p.pad_half_m.z() - palm_half_z;
  TriangleMesh palm =
      flat_box(Vec3(p.pad_half_m.x() * 1.2, 0.5 * max_width + 2.0 * p.pad_half_m.y(), palm_half_z));
  palm.transform(Iso3(Eigen::Translation3d(0.0, 0.0, palm_z)));
  gripper_body_.push_back(scene_.add_mesh(palm, options_.colours.gripper));
  scene_.mesh(gripper_body_.back()).name = "gripper palm";
  const double stem_length = palm_z - palm_half_z;
  if (stem_length > 1e-4) {
    const double r = std::max(p.pad_half_m.x(), 0.01);
    TriangleMesh stem = flat_box(Vec3(r, r, 0.5 * stem_length));
    stem.transform(Iso3(Eigen::Translation3d(0.0, 0.0, 0.5 * stem_length)));
    gripper_body_.push_back(scene_.add_mesh(stem, options_.colours.gripper));
    scene_.mesh(gripper_body_.back()).name = "gripper stem";
  }
  const TriangleMesh pad = flat_box(p.pad_half_m);
  for (int i = 0; i < 2; ++i) {
    pads_[static_cast<std::size_t>(i)] = scene_.add_mesh(pad, options_.colours.pad);
    scene_.mesh(pads_[static_cast<std::size_t>(i)]).name = i == 0 ? "pad +y" : "pad -y";
  }
}

void TeleopScene::set_options(const TeleopSceneOptions& options) {
  options_ = options;
  scene_.mesh(sheet_).colour = options_.colours.sheet;
  for (const MeshId id : gripper_body_) {
    scene_.mesh(id).colour = options_.colours.gripper;
  }
  for (const MeshId id : link_mesh_ids_) {
    scene_.mesh(id).colour = options_.colours.robot;
  }
  pose_from(scratch_);
}

void TeleopScene::update(const TeleopSnapshot& snapshot) {
  // The sheet: re-upload only when a height changed (it stays put while nothing presses it).
  const std::size_t n = std::min(snapshot.sheet_heights_m.size(), sheet_positions_.size());
  bool changed = false;
  for (std::size_t k = 0; k < n; ++k) {
    if (snapshot.sheet_heights_m[k] != uploaded_heights_m_[k]) {
      changed = true;
      break;
    }
  }
  if (changed) {
    for (std::size_t k = 0; k < n; ++k) {
      sheet_positions_[k].z() = snapshot.sheet_heights_m[k];
      uploaded_heights_m_[k] = snapshot.sheet_heights_m[k];
    }
    scene_.update_positions(sheet_, sheet_positions_);
  }
  if (&snapshot != &scratch_) {
    scratch_ = snapshot;  // kept for set_options (vectors keep their capacity)
  }
  pose_from(snapshot);
}

void TeleopScene::update_from_world(const World& world) {
  scratch_.time_s = world.rig()->result.time_s;
  fill_teleop_snapshot(scratch_, world);
  update(scratch_);
}

void TeleopScene::pose_from(const TeleopSnapshot& s) {
  const SerialChain& chain = world_.rig()->slave->chain();
  if (s.slave_q.size() == static_cast<std::size_t>(chain.dof())) {
    chain.frames(s.slave_q, frames_);
  }
  for (const Link& link : links_) {
    const Iso3 X_world_frame =
        link.frame < 0 ? Iso3::Identity() : frames_[static_cast<std::size_t>(link.frame)];
    scene_.mesh(link.mesh).X_world_mesh = X_world_frame * link.X_frame_mesh;
  }
  for (const MeshId id : gripper_body_) {
    scene_.mesh(id).X_world_mesh = s.X_world_tool;
  }
  const ParallelGripperParams& gripper = world_.description().teleop->gripper;
  for (int i = 0; i < 2; ++i) {
    RenderMesh& pad = scene_.mesh(pads_[static_cast<std::size_t>(i)]);
    pad.X_world_mesh = Iso3::Identity();
    pad.X_world_mesh.linear() = s.X_world_tool.linear();
    // As the rig places its pad bodies (stage_place_tools.cpp): +y side first.
    const double side = i == 0 ? 1.0 : -1.0;
    pad.X_world_mesh.translation() =
        s.X_world_tool *
        Vec3(0.0, side * (0.5 * s.gripper_width_m + gripper.pad_half_m.y()), gripper.pad_depth_m);
    pad.colour = s.held ? options_.colours.pad_holding : options_.colours.pad;
  }

  scene_.spheres.clear();
  scene_.segments.clear();
  scene_.shadow_marks.clear();
  scene_.spheres.push_back(
      {s.ball_p_world, world_.description().teleop->ball.radius_m, options_.colours.ball, false});
  if (options_.show_joints) {
    for (std::size_t k = 0; k < joint_radius_m_.size() && k < frames_.size(); ++k) {
      scene_.spheres.push_back(
          {frames_[k].translation(), joint_radius_m_[k], options_.colours.joint, false});
    }
  }
  // The tool point (between the pads) marked on the floor.
  const Vec3 tool_point_world = s.X_world_tool * Vec3(0.0, 0.0, gripper.pad_depth_m);
  scene_.shadow_marks.push_back({tool_point_world, 0.03, 0.005, options_.colours.shadow});
  if (options_.show_master) {
    add_master_lines(s);
  }
}

void TeleopScene::add_master_lines(const TeleopSnapshot& s) {
  const MasterArm& master = *world_.model().master();
  const MasterArmGeometry& g = master.geometry();
  std::array<Iso3, 3> f;
  const Iso3 hand = master.arm().frames(s.master_joint_rad, f);
  const double scale = options_.master_display_scale;
  const Vec3f c = options_.colours.master;
  auto at = [&](const Vec3& p_master) {
    return master_point_world(master_origin_world_, scale, p_master);
  };
  const Vec3 base = at(Vec3::Zero());
  const Vec3 shoulder = at(f[1].translation());
  const Vec3 elbow = at(f[2].translation());
  const Vec3 wrist = at(hand.translation());
  scene_.segments.push_back({base, shoulder, c});
  scene_.segments.push_back({shoulder, elbow, c});
  scene_.segments.push_back({elbow, wrist, c});
  // Fingers: pivots ± gap/2 across the hand (its y), each swung out by its angle from the
  // hand's axis (its z).
  const Vec3 y = hand.linear().col(1);
  const Vec3 z = hand.linear().col(2);
  for (int i = 0; i < 2; ++i) {
    const double side = i == 0 ? 1.0 : -1.0;
    const double a =
        std::clamp(s.master_finger_rad[static_cast<std::size_t>(i)], 0.0, g.finger_open_limit_rad);
    const Vec3 pivot = hand.translation() + side * 0.5 * g.finger_gap_m * y;
    const Vec3 tip = pivot + g.finger_m * (std::cos(a) * z + side * std::sin(a) * y);
    scene_.segments.push_back({at(pivot), at(tip), Vec3f(0.95f, 0.95f, 0.95f)});
  }
  const double r = 0.01 * scale;
  for (const Vec3& p : {base, shoulder, elbow, wrist}) {
    scene_.spheres.push_back({p, r, c, false});
  }
}

}  // namespace hapsim
