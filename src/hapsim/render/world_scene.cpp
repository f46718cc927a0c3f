#include "hapsim/render/world_scene.h"

#include "hapsim/rig/rig_controller.h"
#include "hapsim/world/fem_coupling.h"

#include "hapsim/collision/knee_index.h"
#include "hapsim/collision/sphere_tree.h"
#include "hapsim/core/error.h"
#include "hapsim/render/creased_normals.h"
#include "hapsim/render/force_scale.h"
#include "hapsim/render/hand_figure.h"
#include "hapsim/render/slave_figure.h"
#include "hapsim/render/user_colour.h"
#include "hapsim/rig/slave_shapes.h"

#include <algorithm>
#include <array>
#include <cctype>
#include <cmath>
#include <numbers>
#include <string>

namespace hapsim {

struct WorldScene::Segment {
  std::size_t body = 0;
  std::size_t index_in_body = 0;
  MeshId mesh = 0;
  std::string label;
  Vec3f tissue_colour = Vec3f::Ones();
  bool deformable = false;
  bool sheet = false;    // a Gaussian sheet: shaded by its dent (tissue colouring)
  bool faceted = false;  // drawn with a vertex per triangle corner (no vertex groups)
  int pad = -1;          // a rig's gripper pad (0, 1): green while it holds
  std::uint64_t version = ~std::uint64_t{0};  // none from a snapshot yet
  std::unique_ptr<SphereTree> tree;           // built when a sphere-tree level is first shown
  std::unique_ptr<KneeIndex> knee;            // built when groups or their overlays are first shown
  int group_colour_base = 0;                  // group g's colour: palette_colour(base + g)
  std::vector<Vec3f> group_colours;           // per vertex, built with `knee`
};

namespace {

bool contains(const std::string& haystack, std::string_view needle) {
  return haystack.find(needle) != std::string::npos;
}

/// How a rig draws a body, when it is one of the rig's: its colour, whether it is a box drawn
/// with flat faces, which pad it is, whether it is the floor (drawn as the checked floor).
struct RigRole {
  std::optional<Vec3f> colour;
  bool box = false;
  int pad = -1;
  bool floor = false;
};

RigRole rig_role(const WorldDescription& d, std::size_t b, const RigColours& c) {
  RigRole role;
  if (rig_description(d) == nullptr) {
    return role;
  }
  const TeleopRigDescription& rig = *rig_description(d);
  // Boxes: the pads, the palm and stem, and the links of a chain without meshes.
  const bool box_links =
      std::all_of(rig.slave->link_geometry().begin(), rig.slave->link_geometry().end(),
                  [](const ChainLinkGeometry& g) { return g.mesh.empty(); });
  if (b == rig.ball_body) {
    role.colour = c.ball;
  } else if (b == rig.sheet_body) {
    role.colour = c.sheet;
  } else if (b == rig.floor_body) {
    role.floor = true;
  }
  for (int i = 0; i < 2; ++i) {
    if (b == rig.pad_body[static_cast<std::size_t>(i)]) {
      role = {c.pad, true, i, false};
    }
  }
  for (const TeleopRigDescription::SlaveBody& s : rig.slave_bodies) {
    if (b == s.body) {
      role = {s.frame == kToolFrame ? c.gripper : c.robot, s.frame == kToolFrame || box_links, -1,
              false};
    }
  }
  return role;
}

}  // namespace

Vec3f WorldScene::tissue_colour(std::string_view material_name, int material_index) {
  std::string n(material_name);
  std::transform(n.begin(), n.end(), n.begin(),
                 [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  if (contains(n, "cartilage") || contains(n, "meniscus")) {
    return {0.70f, 0.82f, 0.90f};
  }
  if (contains(n, "bone") || contains(n, "cortical")) {
    return {0.93f, 0.89f, 0.78f};
  }
  if (contains(n, "ligament") || contains(n, "tendon")) {
    return {0.95f, 0.90f, 0.60f};
  }
  if (contains(n, "muscle")) {
    return {0.72f, 0.25f, 0.22f};
  }
  if (contains(n, "skin") || contains(n, "fat")) {
    return {0.94f, 0.76f, 0.64f};
  }
  if (contains(n, "sheet")) {
    return {0.55f, 0.75f, 0.95f};
  }
  if (contains(n, "table") || contains(n, "wood")) {
    return {0.62f, 0.46f, 0.30f};
  }
  if (contains(n, "ball") || contains(n, "rubber")) {
    return {0.95f, 0.55f, 0.15f};
  }
  return palette_colour(material_index);
}

WorldScene::WorldScene(const World& world, WorldSceneOptions options)
    : world_(world), options_(options) {
  const WorldDescription& d = world.description();
  segments_.resize(world.flat_segment_count());
  for (std::size_t b = 0; b < d.bodies.size(); ++b) {
    const BodyDescription& body = d.bodies[b];
    const RigRole role = rig_role(d, b, rig_colours_);
    for (std::size_t s = 0; s < body.segments.size(); ++s) {
      const SegmentDescription& sd = body.segments[s];
      auto seg = std::make_unique<Segment>();
      seg->body = b;
      seg->index_in_body = s;
      seg->label = body.name + "/" + sd.name;
      seg->deformable = body.kind == BodyKind::kDeformable;
      seg->sheet = seg->deformable && body.deformation == BodyDeformation::kGaussianSheet;
      seg->faceted = role.box;
      seg->pad = role.pad;
      const MaterialDescription& m = d.materials.at(sd.material);
      seg->tissue_colour =
          role.colour.value_or(tissue_colour(m.name, static_cast<int>(sd.material)));
      seg->mesh = scene_.add_mesh(role.box ? with_creased_normals(sd.mesh, 0.0) : sd.mesh,
                                  seg->tissue_colour, world.body_pose(b));
      scene_.mesh(seg->mesh).name = seg->label;
      if (seg->sheet || body.deformation == BodyDeformation::kFem) {
        // A sheet is flat at rest: the dent is all its detail. A FEM body's levels would be
        // simplified at rest and then moved far from it: a level's error bound no longer holds.
        scene_.drop_lod_levels(seg->mesh);
      }
      scene_.mesh(seg->mesh).opacity = static_cast<float>(m.opacity);
      // A rig's floor is a slab much wider than the scene: the checked floor stands for it.
      scene_.mesh(seg->mesh).visible = !role.floor;
      for (const Vec3& v : sd.mesh.vertices) {
        if (!role.floor) {
          rest_bounds_world_.extend(body.X_world_body * v);
        }
      }
      segments_[world.flat_segment(BodyIndex{b}, LocalSegment{s}).index()] = std::move(seg);
    }
    body_poses_.push_back(world.body_pose(b));
  }
  scene_.room.visible = options_.show_room;
  has_hand_ = world.model().hand() != nullptr;
  hand_ = world.hand_reading();
  tools_.resize(d.tools.size());
  tool_force_n_.assign(d.tools.size(), 0.0);
  if (rig_description(d) != nullptr) {
    build_rig();
    apply_colouring();
    rebuild_overlays(tools_, tool_force_n_);
    return;
  }
  // A floor just under the bodies, a little wider than them, with 1 cm checks for scale.
  if (!rest_bounds_world_.isEmpty()) {
    const Vec3 c = rest_bounds_world_.center();
    const double half = 0.75 * rest_bounds_world_.sizes().head<2>().maxCoeff() + 0.05;
    scene_.floor.height_m = rest_bounds_world_.min().z() - 0.002;
    scene_.floor.centre_x_m = c.x();
    scene_.floor.centre_y_m = c.y();
    scene_.floor.half_extent_m = half;
    scene_.floor.cell_m = half > 0.3 ? 0.05 : 0.01;
  }
  apply_colouring();
}

WorldScene::~WorldScene() = default;

// The rig's part: its state at the start, the joint spheres of a slave drawn as boxes, the master
// beside the slave's −y side (clear of the ball), on the floor, and a floor under everything.
void WorldScene::build_rig() {
  const TeleopRigDescription& rig = *rig_description(world_.description());
  rig_ = make_teleop_snapshot(world_);
  frames_.resize(static_cast<std::size_t>(rig.slave->dof()));
  slave_figure_ = std::make_unique<SlaveFigure>(*rig.slave, scene_,
                                                SlaveLook{rig_colours_.robot, rig_colours_.joint});
  warnings_ = slave_figure_->warnings();
  show_slave_link_bodies(!slave_figure_->draws_links());
  scene_.style.line_width_px = 2.0f;
  Box3 bounds = rest_bounds_world_;
  const BallEnvironmentOptions& env = rig.environment;
  const double floor_z = env.has_floor ? env.floor_z_m : bounds.min().z();
  bounds.extend(Vec3(bounds.min().x(), bounds.min().y(), floor_z));
  const MasterArmGeometry& g = rig_controller(world_.description())->master().geometry();
  const double master_reach =
      options_.master_display_scale * (g.upper_arm_m + g.forearm_m + g.finger_m);
  master_origin_world_ = Vec3(bounds.center().x(), bounds.min().y() - 0.6 * master_reach, floor_z);
  if (options_.show_master) {
    add_master(*rig_);
    for (const RenderCapsule& c : scene_.capsules) {
      bounds.extend(c.a_world);
      bounds.extend(c.b_world);
    }
    scene_.capsules.clear();
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

// A sheet's dent is a fraction of a millimetre under a resting ball (its grid is centimetres
// apart): too shallow to change the shading, so the sheet is coloured by how deep each node is
// below rest, darker blue down to kDentFullScaleM.
void WorldScene::shade_dent(Segment& seg) {
  constexpr double kDentFullScaleM = 5e-4;
  const Vec3f deep(0.10f, 0.22f, 0.55f);
  const std::vector<Vec3>& vertices = scene_.mesh(seg.mesh).geometry().vertices;
  scratch_colours_.resize(vertices.size());
  for (std::size_t v = 0; v < vertices.size(); ++v) {
    const auto u = static_cast<float>(std::clamp(-vertices[v].z() / kDentFullScaleM, 0.0, 1.0));
    scratch_colours_[v] = (1.0f - u) * seg.tissue_colour + u * deep;
  }
  scene_.set_vertex_colours(seg.mesh, scratch_colours_);
}

// The sheet's grid lines over its shaded faces, on its live surface: the dent bends them where a
// press or a resting ball pushed it in. Lifted a little off the faces (along the sheet's normal)
// so the depth test keeps them in front.
void WorldScene::add_sheet_grid(const Segment& seg) {
  constexpr double kLiftM = 3e-4;
  const Vec3f line(0.22f, 0.36f, 0.62f);
  const std::vector<Vec3>& v = scene_.mesh(seg.mesh).geometry().vertices;
  const auto n =
      static_cast<std::size_t>(world_.description().bodies[seg.body].sheet.nodes_per_side);
  if (n < 2 || v.size() != n * n) {
    return;
  }
  const Iso3& X = body_poses_[seg.body];
  const Vec3 lift = kLiftM * X.linear().col(2);
  const auto at = [&](std::size_t i, std::size_t j) { return Vec3(X * v[j * n + i] + lift); };
  for (std::size_t a = 0; a < n; ++a) {
    for (std::size_t b = 0; b + 1 < n; ++b) {
      scene_.segments.push_back({at(b, a), at(b + 1, a), line});
      scene_.segments.push_back({at(a, b), at(a, b + 1), line});
    }
  }
}

// Whether the hand's reading puts each fingertip where its tool is. A served world's views carry
// the glove's reading with the tools, but a view from an older host, or a reading from another
// cycle than the tools, would draw the hand elsewhere and mislead (the fingertips alone are drawn
// then).
bool WorldScene::hand_agrees_with_tools() const {
  constexpr double kToleranceM = 1e-4;
  const auto tips = world_.model().hand()->fingertips_world(hand_);
  const WorldDescription& d = world_.description();
  for (std::size_t t = 0; t < tools_.size() && t < d.tools.size(); ++t) {
    const int f = d.tools[t].finger;
    if (f >= 0 && f < kHandFingers &&
        !((tips[static_cast<std::size_t>(f)] - tools_[t].p_world).norm() <= kToleranceM)) {
      return false;
    }
  }
  return true;
}

MeshId WorldScene::segment_mesh(std::size_t flat_segment) const {
  return segments_.at(flat_segment)->mesh;
}

void WorldScene::set_options(const WorldSceneOptions& options) {
  const bool recolour = options.colouring != options_.colouring;
  if (options.show_room != options_.show_room) {
    scene_.room.visible = options.show_room;
  }
  options_ = options;
  if (recolour) {
    apply_colouring();
  }
  rebuild_overlays(tools_, tool_force_n_);
}

void WorldScene::set_segment_visible(std::size_t flat_segment, bool visible) {
  scene_.mesh(segments_.at(flat_segment)->mesh).visible = visible;
}

bool WorldScene::segment_visible(std::size_t flat_segment) const {
  return scene_.mesh(segments_.at(flat_segment)->mesh).visible;
}

const std::string& WorldScene::segment_label(std::size_t flat_segment) const {
  return segments_.at(flat_segment)->label;
}

const KneeIndex& WorldScene::knee_index(Segment& seg) {
  if (!seg.knee) {
    const TriangleMesh& rest =
        world_.description().bodies[seg.body].segments[seg.index_in_body].mesh;
    seg.knee = std::make_unique<KneeIndex>(rest);
    seg.group_colour_base = next_group_colour_;
    next_group_colour_ += static_cast<int>(seg.knee->group_count());
    seg.group_colours.resize(rest.vertices.size());
    for (std::size_t v = 0; v < rest.vertices.size(); ++v) {
      seg.group_colours[v] =
          palette_colour(seg.group_colour_base +
                         static_cast<int>(seg.knee->vertex_group(static_cast<std::uint32_t>(v))));
    }
  }
  return *seg.knee;
}

// The knee method's overlays belong to the segments it could answer for: shown, and neither a
// sheet (its own field answers) nor a box drawn with flat faces.
bool WorldScene::knee_overlays_apply(const Segment& seg) const {
  return scene_.mesh(seg.mesh).visible && !seg.sheet && !seg.faceted;
}

// A sphere as three great circles (in the world's xy, yz and zx planes): lines light enough
// that a dozen overlapping spheres still let the surface they wrap be seen.
void WorldScene::add_circles(const Vec3& centre_world, double radius_m, const Vec3f& colour) {
  constexpr int kSteps = 48;
  for (int axis = 0; axis < 3; ++axis) {
    const Vec3 u = Vec3::Unit((axis + 1) % 3);
    const Vec3 v = Vec3::Unit((axis + 2) % 3);
    const auto at = [&](int k) {
      const double a = 2.0 * std::numbers::pi * k / kSteps;
      return Vec3(centre_world + radius_m * (std::cos(a) * u + std::sin(a) * v));
    };
    for (int k = 0; k < kSteps; ++k) {
      scene_.segments.push_back({at(k), at(k + 1), colour});
    }
  }
}

// The knee paper's Fig. 3: "the dark lines represent the spheres of influence of each group" and
// "the three dark spheres near the tip of the finger represent the three vertices closest to the
// point of possible contact".
void WorldScene::add_knee_overlays() {
  const auto dark = [](const Vec3f& c) { return Vec3f(0.45f * c); };
  if (options_.show_influence_spheres) {
    for (auto& seg : segments_) {
      if (!knee_overlays_apply(*seg)) {
        continue;
      }
      const KneeIndex& knee = knee_index(*seg);
      const Iso3& X = body_poses_[seg->body];
      for (std::uint32_t g = 0; g < knee.group_count(); ++g) {
        add_circles(X * knee.group_centroid(g), knee.group_radius(g),
                    dark(palette_colour(seg->group_colour_base + static_cast<int>(g))));
      }
    }
  }
  if (!options_.show_contact_vertices) {
    return;
  }
  const WorldDescription& d = world_.description();
  const Vec3f marker(0.06f, 0.06f, 0.08f);
  for (std::size_t tool = 0; tool < tools_.size() && tool < d.tools.size(); ++tool) {
    // The paper's "point of possible contact": the centre of a tool that touches something (the
    // skin over a shown muscle counts), as the method queries it, against the shown segment whose
    // surface the method finds nearest, within a centimetre of the tool's surface.
    if (tools_[tool].contact_count == 0) {
      continue;
    }
    const double radius = d.tools[tool].radius_m;
    Segment* nearest = nullptr;
    KneeQueryTrace trace;
    double nearest_gap_m = 0.01;
    for (auto& seg : segments_) {
      if (!knee_overlays_apply(*seg)) {
        continue;
      }
      const Vec3 p_body = body_poses_[seg->body].inverse() * tools_[tool].p_world;
      const KneeIndex& knee = knee_index(*seg);
      const SurfacePoint sp = knee.closest_point(p_body);
      if (sp.found() && sp.signed_distance - radius < nearest_gap_m) {
        nearest_gap_m = sp.signed_distance - radius;
        nearest = seg.get();
        trace = knee.trace(p_body);
      }
    }
    if (nearest == nullptr) {
      continue;
    }
    // Where the vertices are drawn now (a deformed segment's dent moves them).
    const std::vector<Vec3>& now = scene_.mesh(nearest->mesh).geometry().vertices;
    const Iso3& X = body_poses_[nearest->body];
    const double r = std::max(0.0008, 0.2 * radius);
    std::array<Vec3, 3> p;
    for (std::size_t k = 0; k < trace.vertex_count; ++k) {
      p[k] = X * now[trace.closest_vertices[k]];
      scene_.spheres.push_back({p[k], r, marker, false});
    }
    if (trace.vertex_count == 3) {
      for (std::size_t k = 0; k < 3; ++k) {
        scene_.segments.push_back({p[k], p[(k + 1) % 3], marker});
      }
    }
  }
}

void WorldScene::apply_colouring() {
  for (std::size_t i = 0; i < segments_.size(); ++i) {
    Segment& seg = *segments_[i];
    RenderMesh& mesh = scene_.mesh(seg.mesh);
    switch (options_.colouring) {
      case SegmentColouring::kTissue:
      case SegmentColouring::kStress:  // FEM bodies are shaded as their stress comes
        mesh.colour = seg.tissue_colour;
        scene_.set_vertex_colours(seg.mesh, {});
        if (seg.sheet) {
          shade_dent(seg);
        }
        break;
      case SegmentColouring::kSegments:
        mesh.colour = palette_colour(static_cast<int>(i));
        scene_.set_vertex_colours(seg.mesh, {});
        break;
      case SegmentColouring::kGroups: {
        if (seg.faceted) {
          mesh.colour = seg.tissue_colour;  // a box: no vertex groups to show
          scene_.set_vertex_colours(seg.mesh, {});
          break;
        }
        (void)knee_index(seg);
        scene_.set_vertex_colours(seg.mesh, seg.group_colours);
        break;
      }
    }
  }
}

void WorldScene::update(const WorldSnapshot& snapshot) {
  if (snapshot.body_poses_world.size() == body_poses_.size()) {
    body_poses_ = snapshot.body_poses_world;
  }
  for (std::size_t i = 0; i < segments_.size(); ++i) {
    Segment& seg = *segments_[i];
    scene_.mesh(seg.mesh).X_world_mesh = body_poses_[seg.body];
    // A FEM body's surface is not in the snapshot (update_fem_surfaces): its slot stays empty.
    if (!seg.deformable || i >= snapshot.positions_body.size() ||
        snapshot.positions_version[i] == seg.version || snapshot.positions_body[i].empty()) {
      continue;
    }
    const std::vector<float>& xyz = snapshot.positions_body[i];
    scratch_positions_.resize(xyz.size() / 3);
    for (std::size_t v = 0; v < scratch_positions_.size(); ++v) {
      scratch_positions_[v] = Vec3(xyz[3 * v], xyz[3 * v + 1], xyz[3 * v + 2]);
    }
    scene_.update_positions(seg.mesh, scratch_positions_);
    seg.version = snapshot.positions_version[i];
    if (seg.sheet && options_.colouring == SegmentColouring::kTissue) {
      shade_dent(seg);
    }
  }
  if (rig_ && snapshot.teleop) {
    *rig_ = *snapshot.teleop;  // sized alike: no allocation after the first
  }
  hand_ = snapshot.hand;
  rebuild_overlays(snapshot.tools, snapshot.tool_force_n);
}

void WorldScene::update_fem_surfaces(World& world) {
  FemCoupling* fem = world.fem();
  if (fem == nullptr) {
    return;
  }
  for (std::size_t b = 0; b < fem->body_count(); ++b) {
    const FemSurfaceFrame* frame = fem->take_published_surface(b);
    if (frame == nullptr) {
      continue;
    }
    for (const auto& seg : segments_) {
      if (seg->body == fem->world_body(b)) {
        scene_.update_positions(seg->mesh, frame->vertices);
        if (options_.colouring == SegmentColouring::kStress) {
          shade_stress(*seg, frame->von_mises_pa);
        }
      }
    }
  }
}

// Tissue colour at no stress, yellow at half the frame's largest, red at it: where the tissue is
// loaded, at a glance (the scale is the viewer's legend).
void WorldScene::shade_stress(Segment& seg, std::span<const float> von_mises_pa) {
  const std::vector<Vec3>& vertices = scene_.mesh(seg.mesh).geometry().vertices;
  if (von_mises_pa.size() != vertices.size()) {
    return;
  }
  double full = 0.0;
  for (const float s : von_mises_pa) {
    full = std::max(full, static_cast<double>(s));
  }
  fem_stress_full_scale_pa_ = full;
  const Vec3f yellow(0.95f, 0.85f, 0.2f);
  const Vec3f red(0.85f, 0.1f, 0.08f);
  scratch_colours_.resize(vertices.size());
  for (std::size_t v = 0; v < vertices.size(); ++v) {
    const auto u =
        full > 0.0
            ? static_cast<float>(std::clamp(static_cast<double>(von_mises_pa[v]) / full, 0.0, 1.0))
            : 0.0f;
    scratch_colours_[v] = u < 0.5f ? (1.0f - 2.0f * u) * seg.tissue_colour + 2.0f * u * yellow
                                   : (2.0f - 2.0f * u) * yellow + (2.0f * u - 1.0f) * red;
  }
  scene_.set_vertex_colours(seg.mesh, scratch_colours_);
}

void WorldScene::update_from_world(const World& world) {
  for (std::size_t b = 0; b < body_poses_.size(); ++b) {
    body_poses_[b] = world.body_pose(b);
  }
  for (const auto& seg : segments_) {
    scene_.mesh(seg->mesh).X_world_mesh = body_poses_[seg->body];
    if (seg->deformable) {
      scene_.update_positions(seg->mesh, world.surface(seg->body, seg->index_in_body).vertices);
      if (seg->sheet && options_.colouring == SegmentColouring::kTissue) {
        shade_dent(*seg);
      }
      if (const FemCoupling* fem = world.fem();
          fem != nullptr && options_.colouring == SegmentColouring::kStress) {
        for (std::size_t b = 0; b < fem->body_count(); ++b) {
          if (fem->world_body(b) == seg->body) {
            shade_stress(*seg, fem->surface_von_mises_pa(b));
          }
        }
      }
    }
  }
  hand_ = world.hand_reading();
  if (rig_) {
    rig_->time_s = rig_state(world)->result.time_s;
    fill_teleop_snapshot(*rig_, world);
  }
  const StepResult& r = world.last_result();
  std::vector<double> force_n(r.tools.size());
  for (std::size_t t = 0; t < r.tools.size(); ++t) {
    force_n[t] = r.tools[t].force_world_n.norm();
  }
  rebuild_overlays({r.tools.begin(), r.tools.end()}, force_n);
}

void WorldScene::rebuild_overlays(const std::vector<ToolState>& tools,
                                  const std::vector<double>& force_n) {
  if (&tools != &tools_) {
    tools_ = tools;
  }
  if (&force_n != &tool_force_n_) {
    tool_force_n_ = force_n;
  }
  const WorldDescription& d = world_.description();
  if (!rest_bounds_world_.isEmpty()) {
    scene_.room.height_m = 1.3 * (rest_bounds_world_.max().z() - scene_.floor.height_m) + 0.05;
  }
  const double heat_full_scale_n = options_.force_full_scale_n > 0.0
                                       ? options_.force_full_scale_n
                                       : force_display_scale_n(d, 0.0);
  scene_.spheres.clear();
  scene_.capsules.clear();
  scene_.segments.clear();
  scene_.shadow_marks.clear();
  if (has_hand_ && hand_agrees_with_tools()) {
    add_hand_figure(*world_.model().hand(), hand_, kHandColour, scene_.capsules);
  }
  const double scale =
      std::max(0.05, rest_bounds_world_.isEmpty() ? 0.1 : rest_bounds_world_.sizes().norm());
  for (std::size_t t = 0; t < tools_.size() && t < d.tools.size(); ++t) {
    const ToolState& tool = tools_[t];
    if (!tool.present) {
      continue;  // another user's tool whose device host is not there
    }
    const double f = t < tool_force_n_.size() ? tool_force_n_[t] : 0.0;
    // Each user's colour when free (render/user_colour.h; the first's green, or the hand's),
    // towards red as the force grows to the display's full scale.
    const float heat = static_cast<float>(std::clamp(f / heat_full_scale_n, 0.0, 1.0));
    const double radius = std::max(d.tools[t].radius_m, 0.002);
    const Vec3f cool = d.tools[t].device > 0 ? user_colour(d.tools[t].device)
                                             : (has_hand_ ? kHandColour : user_colour(0));
    scene_.spheres.push_back({tool.p_world, radius,
                              Vec3f((1.0f - heat) * cool + heat * Vec3f(0.95f, 0.2f, 0.25f)),
                              false});
    if (options_.show_proxies && (tool.proxy_world - tool.p_world).norm() > 1e-4) {
      scene_.spheres.push_back({tool.proxy_world, radius, Vec3f(0.3f, 0.6f, 1.0f), true});
      scene_.segments.push_back({tool.p_world, tool.proxy_world, Vec3f(0.3f, 0.6f, 1.0f)});
    }
    if (options_.show_force_arrows && tool.force_world_n.norm() > 1e-6) {
      scene_.segments.push_back({tool.p_world,
                                 tool.p_world + options_.arrow_m_per_n * tool.force_world_n,
                                 Vec3f(1.0f, 0.9f, 0.1f)});
    }
    scene_.shadow_marks.push_back(
        {tool.p_world, 0.04 * scale, 0.006 * scale, Vec3f(0.1f, 0.1f, 0.12f)});
  }
  // The floor grows to hold every tool's shadow mark (a hand comes from beyond the knee's floor).
  RenderFloor& fl = scene_.floor;
  for (const ShadowMark& mark : scene_.shadow_marks) {
    const double reach = std::max(std::abs(mark.point_world.x() - fl.centre_x_m),
                                  std::abs(mark.point_world.y() - fl.centre_y_m)) +
                         2.0 * mark.arm_m;
    if (std::isfinite(reach) && reach > fl.half_extent_m) {
      fl.half_extent_m = fl.cell_m * std::ceil(reach / fl.cell_m);
    }
  }
  for (const auto& seg : segments_) {
    if (seg->sheet && scene_.mesh(seg->mesh).visible) {
      add_sheet_grid(*seg);
    }
  }
  if (options_.sphere_tree_level >= 0) {
    for (auto& seg : segments_) {
      if (!scene_.mesh(seg->mesh).visible) {
        continue;
      }
      if (!seg->tree) {
        seg->tree =
            std::make_unique<SphereTree>(d.bodies[seg->body].segments[seg->index_in_body].mesh);
      }
      const Iso3& X = body_poses_[seg->body];
      const auto level = static_cast<std::size_t>(options_.sphere_tree_level);
      for (std::size_t n = 0; n < seg->tree->node_count(); ++n) {
        const std::size_t node_level = seg->tree->node_level(n);
        // A leaf above the chosen level stands in for its missing descendants.
        if (node_level == level || (node_level < level && seg->tree->node_children(n).empty())) {
          const Sphere s = seg->tree->node_sphere(n);
          scene_.spheres.push_back(
              {X * s.center, s.radius, palette_colour(static_cast<int>(n % 10)), true});
        }
      }
    }
  }
  add_knee_overlays();
  if (rig_) {
    add_rig_overlays();
  }
}

// The slave's link bodies (collision shapes) drawn, or hidden behind the figure that draws the
// links itself.
void WorldScene::show_slave_link_bodies(bool visible) {
  for (const TeleopRigDescription::SlaveBody& s :
       rig_description(world_.description())->slave_bodies) {
    if (s.frame != kToolFrame) {
      scene_.mesh(segments_[world_.flat_segment(BodyIndex{s.body}, LocalSegment{0}).index()]->mesh)
          .visible = visible;
    }
  }
}

// What only a rig has, from its snapshot: the pads' colour while they hold, the joint spheres,
// the shadow mark under the gripper's tool point (between the pads), the master.
void WorldScene::add_rig_overlays() {
  const TeleopSnapshot& s = *rig_;
  const TeleopRigDescription& rig = *rig_description(world_.description());
  if (options_.colouring == SegmentColouring::kTissue) {
    for (const auto& seg : segments_) {
      if (seg->pad >= 0) {
        scene_.mesh(seg->mesh).colour = s.held ? rig_colours_.pad_holding : rig_colours_.pad;
      }
    }
  }
  if (s.slave_q.size() == frames_.size()) {
    const Iso3 tip_world = rig.slave->frames(s.slave_q, frames_);
    slave_figure_->update(frames_, tip_world, scene_, options_.show_joints);
  }
  const Vec3 tool_point_world = s.X_world_tool * Vec3(0.0, 0.0, rig.gripper.pad_depth_m);
  scene_.shadow_marks.push_back({tool_point_world, 0.03, 0.005, rig_colours_.shadow});
  if (options_.show_master) {
    add_master(s);
  }
}

// The master arm at master_display_scale beside the slave: its links as rods from the base
// through the shoulder and elbow to the hand, its two fingers as thin rods.
void WorldScene::add_master(const TeleopSnapshot& s) {
  const MasterArm& master = rig_controller(world_.description())->master();
  const MasterArmGeometry& g = master.geometry();
  std::array<Iso3, 3> f;
  const Iso3 hand = master.arm().frames(s.master_joint_rad, f);
  const double scale = options_.master_display_scale;
  const Vec3f c = rig_colours_.master;
  const auto at = [&](const Vec3& p_master) {
    return Vec3(master_origin_world_ + scale * p_master);
  };
  const Vec3 base = at(Vec3::Zero());
  const Vec3 shoulder = at(f[1].translation());
  const Vec3 elbow = at(f[2].translation());
  const Vec3 wrist = at(hand.translation());
  const double r = 0.02 * scale;
  scene_.capsules.push_back({base, base + Vec3(0.0, 0.0, 0.5 * r), 2.2 * r, rig_colours_.joint});
  scene_.capsules.push_back({base, shoulder, r, c});
  scene_.capsules.push_back({shoulder, elbow, r, c});
  scene_.capsules.push_back({elbow, wrist, 0.8 * r, c});
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
    scene_.capsules.push_back({at(pivot), at(tip), 0.4 * r, Vec3f(0.92f, 0.92f, 0.92f)});
  }
}

}  // namespace hapsim
