#include "hapsim/rig/rig_world.h"

#include "hapsim/core/error.h"
#include "hapsim/force/contact_material.h"
#include "hapsim/geometry/procedural.h"
#include "hapsim/rig/rig_controller.h"

#include <memory>
#include <utility>

namespace hapsim {

namespace {

// A rig contact spring as a penalty material: the same stiffness, damping and friction; no
// penetration limit (a spring); the force capped at `max_force_n`.
MaterialDescription spring_material(std::string name, const ContactSpring& spring,
                                    double max_force_n = 1e6) {
  MaterialDescription m;
  m.name = std::move(name);
  m.response = ContactResponse::kPenalty;
  m.contact.stiffness_n_per_m = spring.stiffness_n_per_m;
  m.contact.damping_n_s_per_m = spring.damping_n_s_per_m;
  m.contact.static_friction = spring.friction;
  m.contact.dynamic_friction = spring.friction;
  m.contact.max_penetration_m = 1.0;
  m.contact.max_force_n = max_force_n;
  return m;
}

BodyDescription rig_body(std::string name, BodyKind kind, const Iso3& X_world_body,
                         TriangleMesh mesh, std::uint32_t material) {
  BodyDescription b;
  b.name = name;
  b.kind = kind;
  b.X_world_body = X_world_body;
  SegmentDescription s;
  s.name = std::move(name);
  s.material = material;
  s.mesh = std::move(mesh);
  b.segments.push_back(std::move(s));
  return b;
}

// The slave's pads, links, palm and stem as kinematic bodies of `d`, at its start joints (as
// its follower clamps them) with the gripper open: where the rig's place stage will put them on
// the first step. Their body indices go into `rig`.
void add_slave_bodies(WorldDescription& d, TeleopRigDescription& rig, std::uint32_t pad_material,
                      std::uint32_t link_material) {
  const SerialChain& chain = *rig.slave;
  std::vector<double> q = rig.slave_start_rad;
  q.resize(static_cast<std::size_t>(chain.dof()), 0.0);
  chain.clamp_to_limits(q);
  std::vector<Iso3> frames(static_cast<std::size_t>(chain.dof()));
  const Iso3 X_world_tool = chain.frames(q, frames);
  const auto frame_pose = [&](int frame) {
    return frame == kToolFrame ? X_world_tool
           : frame < 0         ? Iso3::Identity()
                               : frames[static_cast<std::size_t>(frame)];
  };
  const double open_half_m = 0.5 * rig.follower.gripper_max_width_m + rig.gripper.pad_half_m.y();
  for (std::size_t i = 0; i < 2; ++i) {
    rig.pad_body[i] = d.bodies.size();
    const double side = i == 0 ? 1.0 : -1.0;
    d.bodies.push_back(rig_body(
        i == 0 ? "pad_plus_y" : "pad_minus_y", BodyKind::kKinematic,
        X_world_tool * Eigen::Translation3d(0.0, side * open_half_m, rig.gripper.pad_depth_m),
        make_box(rig.gripper.pad_half_m), pad_material));
  }
  // The slave's own links, palm and stem: kinematic too, so they push the ball as the pads do.
  std::vector<SlaveShape> shapes = slave_link_shapes(chain);
  for (SlaveShape& s : gripper_shapes(rig.gripper, rig.follower.gripper_max_width_m)) {
    shapes.push_back(std::move(s));
  }
  rig.slave_bodies.clear();
  for (SlaveShape& s : shapes) {
    rig.slave_bodies.push_back({d.bodies.size(), s.frame, s.X_frame_mesh});
    d.bodies.push_back(rig_body("slave_" + s.name, BodyKind::kKinematic,
                                frame_pose(s.frame) * s.X_frame_mesh, std::move(s.mesh),
                                link_material));
  }
}

}  // namespace

WorldDescription rig_world(TeleopRigDescription rig, std::string name) {
  WorldDescription d;
  d.name = std::move(name);
  // The ball is rigid: in series with it, each pair is the other body's spring.
  MaterialDescription ball_material = spring_material("ball", ContactSpring{});
  ball_material.contact.stiffness_n_per_m = kRigidStiffness_n_per_m;
  ball_material.contact.damping_n_s_per_m = kRigidDamping_n_s_per_m;
  ball_material.contact.static_friction = 0.0;
  ball_material.contact.dynamic_friction = 0.0;
  d.materials = {std::move(ball_material), spring_material("sheet", rig.environment.sheet_contact),
                 spring_material("floor", rig.environment.floor_contact)};
  if (rig.environment.has_floor) {
    rig.floor_body = d.bodies.size();
    const Vec3 half(2.0, 2.0, 0.05);
    d.bodies.push_back(
        rig_body("floor", BodyKind::kStatic,
                 Iso3(Eigen::Translation3d(0.0, 0.0, rig.environment.floor_z_m - half.z())),
                 make_box(half), 2));
  }
  rig.sheet_body = d.bodies.size();
  BodyDescription sheet = rig_body("sheet", BodyKind::kDeformable, rig.environment.X_world_sheet,
                                   make_sheet(rig.sheet.nodes_per_side, rig.sheet.side_m), 1);
  sheet.segments.front().two_sided = true;
  sheet.deformation = BodyDeformation::kGaussianSheet;
  sheet.sheet = rig.sheet;
  d.bodies.push_back(std::move(sheet));
  rig.ball_body = d.bodies.size();
  const double r = rig.ball.radius_m;
  BodyDescription ball =
      rig_body("ball", BodyKind::kDynamic, Iso3(Eigen::Translation3d(rig.ball_start_world)),
               make_uv_sphere(r, 32, 16), 0);
  ball.segments.front().sphere = ExactSphere{Vec3::Zero(), r};
  ball.rigid.mass_kg = rig.ball.mass_kg;
  ball.rigid.inertia_kg_m2 = Mat3::Identity() * 0.4 * rig.ball.mass_kg * r * r;
  d.bodies.push_back(std::move(ball));
  d.gravity_m_per_s2 = rig.ball.gravity_m_per_s2;
  return add_rig(std::move(d), std::move(rig));
}

WorldDescription add_rig(WorldDescription world, TeleopRigDescription rig) {
  for (const char* name : {"slave_pad", "slave_link"}) {
    for (const MaterialDescription& m : world.materials) {
      if (m.name == name) {
        throw Error("rig", std::string("the scene already has a material named '") + name +
                               "', which the rig adds for its gripper pads and links");
      }
    }
  }
  const auto pad_material = static_cast<std::uint32_t>(world.materials.size());
  world.materials.push_back(
      spring_material("slave_pad", rig.gripper.pad_contact, rig.gripper.max_force_n));
  world.materials.push_back(spring_material("slave_link", rig.gripper.pad_contact));
  add_slave_bodies(world, rig, pad_material, pad_material + 1);
  world.controller = std::make_shared<RigController>(std::move(rig));
  return world;
}

}  // namespace hapsim
