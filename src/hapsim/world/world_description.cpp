#include "hapsim/world/world_description.h"

#include "hapsim/geometry/procedural.h"

#include <algorithm>
#include <cstdio>

namespace hapsim {

std::string_view to_string(ContactResponse response) {
  return response == ContactResponse::kProxy ? "proxy" : "penalty";
}

std::string_view to_string(ContactMethod method) {
  switch (method) {
    case ContactMethod::kExact:
      return "exact";
    case ContactMethod::kSphereTree:
      return "spheretree";
    case ContactMethod::kKnee:
      return "knee";
  }
  return "unknown";
}

std::optional<ContactMethod> parse_contact_method(std::string_view name) {
  for (const ContactMethod m :
       {ContactMethod::kExact, ContactMethod::kSphereTree, ContactMethod::kKnee}) {
    if (name == to_string(m)) {
      return m;
    }
  }
  return std::nullopt;
}

std::string_view to_string(BodyKind kind) {
  switch (kind) {
    case BodyKind::kStatic:
      return "static";
    case BodyKind::kDynamic:
      return "dynamic";
    case BodyKind::kDeformable:
      return "deformable";
    case BodyKind::kKinematic:
      return "kinematic";
  }
  return "unknown";
}

std::string_view to_string(BodyDeformation deformation) {
  switch (deformation) {
    case BodyDeformation::kGaussianSheet:
      return "sheet";
    case BodyDeformation::kFem:
      return "fem";
    case BodyDeformation::kVertexDeflection:
      break;
  }
  return "deflection";
}

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

}  // namespace

WorldDescription rig_world(TeleopRigDescription rig, std::string name) {
  WorldDescription d;
  d.name = std::move(name);
  // The ball is rigid: in series with it, each pair is the other body's spring.
  ContactSpring rigid;
  rigid.stiffness_n_per_m = 1e12;
  rigid.damping_n_s_per_m = 1e12;
  rigid.friction = 0.0;
  d.materials = {spring_material("ball", rigid),
                 spring_material("sheet", rig.environment.sheet_contact),
                 spring_material("pad", rig.gripper.pad_contact, rig.gripper.max_force_n),
                 spring_material("floor", rig.environment.floor_contact),
                 spring_material("link", rig.gripper.pad_contact)};
  if (rig.environment.has_floor) {
    rig.floor_body = d.bodies.size();
    const Vec3 half(2.0, 2.0, 0.05);
    d.bodies.push_back(
        rig_body("floor", BodyKind::kStatic,
                 Iso3(Eigen::Translation3d(0.0, 0.0, rig.environment.floor_z_m - half.z())),
                 make_box(half), 3));
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
  // The slave at its start joints (as its follower clamps them), the gripper open: where the
  // rig's place stage will put its bodies on the first step.
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
        make_box(rig.gripper.pad_half_m), 2));
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
                                frame_pose(s.frame) * s.X_frame_mesh, std::move(s.mesh), 4));
  }
  d.teleop = std::move(rig);
  return d;
}

namespace {

// FNV-1a, 64 bit: a stable content fingerprint (not a security hash).
class Fnv64 {
 public:
  void bytes(const void* data, std::size_t n) {
    const auto* p = static_cast<const unsigned char*>(data);
    for (std::size_t i = 0; i < n; ++i) {
      h_ = (h_ ^ p[i]) * 1099511628211ULL;
    }
  }
  void number(double x) { bytes(&x, sizeof x); }
  void text(const std::string& s) {
    bytes(s.data(), s.size());
    number(static_cast<double>(s.size()));
  }
  [[nodiscard]] std::uint64_t value() const { return h_; }

 private:
  std::uint64_t h_ = 14695981039346656037ULL;
};

}  // namespace

std::string content_hash(const WorldDescription& description) {
  Fnv64 h;
  h.text(description.name);
  for (const MaterialDescription& m : description.materials) {
    h.text(m.name);
    const ContactMaterial& c = m.contact;
    for (double x : {c.stiffness_n_per_m, c.max_penetration_m, c.max_force_n, c.damping_n_s_per_m,
                     c.static_friction, c.dynamic_friction, m.deflection.elasticity_factor,
                     m.deflection.recovery_time_constant_s, m.deflection.max_recovery_speed_m_per_s,
                     m.deflection.max_deflection_m}) {
      h.number(x);
    }
    h.number(static_cast<double>(m.response));
  }
  for (const BodyDescription& b : description.bodies) {
    h.text(b.name);
    h.number(static_cast<double>(b.kind));
    h.number(static_cast<double>(b.method));
    h.bytes(b.X_world_body.matrix().data(), sizeof(double) * 16);
    // Only what steps differently is hashed, and only where it is used, so that worlds without
    // dynamic bodies or sheets keep the hashes their recordings carry.
    if (b.kind == BodyKind::kDynamic) {
      const RigidBodyDescription& r = b.rigid;
      h.number(r.mass_kg);
      h.bytes(r.com_body.data(), sizeof(double) * 3);
      h.bytes(r.inertia_kg_m2.data(), sizeof(double) * 9);
      h.bytes(r.v_world.data(), sizeof(double) * 3);
      h.bytes(r.w_world.data(), sizeof(double) * 3);
    }
    if (b.kind == BodyKind::kDeformable && b.deformation == BodyDeformation::kGaussianSheet) {
      h.text("sheet");
      h.number(b.sheet.nodes_per_side);
      h.number(b.sheet.side_m);
      h.number(b.sheet.max_depth_m);
      h.number(b.sheet_profile.cutoff_radius_m);
      h.number(b.sheet_profile.width_m);
      h.number(b.sheet_profile.sensitivity_n_per_m);
    }
    if (b.kind == BodyKind::kDeformable && b.deformation == BodyDeformation::kFem && b.fem) {
      // The volume, its materials, supports and solver: all of it steps differently.
      const FemBodyDescription& f = *b.fem;
      h.text("fem");
      for (const Vec3& v : f.tets.nodes) {
        h.bytes(v.data(), sizeof(double) * 3);
      }
      for (const TetIndices& t : f.tets.tets) {
        h.bytes(t.data(), sizeof(std::uint32_t) * 4);
      }
      for (const std::int32_t r : f.tets.regions) {
        h.number(r);
      }
      for (const FemRegionMaterial& m : f.materials) {
        for (const double x : {static_cast<double>(m.region), m.material.youngs_modulus_pa,
                               m.material.poisson_ratio, m.material.density_kg_per_m3,
                               m.material.rayleigh_mass_per_s, m.material.rayleigh_stiffness_s}) {
          h.number(x);
        }
      }
      for (const double x :
           {static_cast<double>(f.options.elasticity), static_cast<double>(f.options.integration),
            f.options.dt_s, static_cast<double>(f.options.max_cg_iterations),
            f.options.cg_relative_tolerance, static_cast<double>(f.options.quasi_static_iterations),
            f.fixed_below_z_m.value_or(-kInf), f.contact_patch_radius_m, f.contact_margin_m,
            f.embedded_surface ? 1.0 : 0.0}) {
        h.number(x);
      }
      h.bytes(f.options.gravity_m_per_s2.data(), sizeof(double) * 3);
      for (const std::uint32_t n : f.fixed_nodes) {
        h.number(n);
      }
      for (const FemAttachment& a : f.attached_to) {
        h.text(a.body);
        h.text(a.segment);
        h.number(a.within_m);
      }
    }
    for (const SegmentDescription& s : b.segments) {
      h.text(s.name);
      h.number(s.material);
      h.number(s.two_sided ? 1.0 : 0.0);
      if (s.csg) {
        // Contact comes from the solid, not the mesh; the mesh (hashed below) polygonises it.
        h.text("csg");
        h.number(static_cast<double>(s.csg->node_count()));
      }
      if (s.sphere) {
        h.text("sphere");
        h.bytes(s.sphere->center_body.data(), sizeof(double) * 3);
        h.number(s.sphere->radius_m);
      }
      for (const Vec3& v : s.mesh.vertices) {
        h.bytes(v.data(), sizeof(double) * 3);
      }
      for (const TriangleIndices& tri : s.mesh.triangles) {
        h.bytes(tri.data(), sizeof(std::uint32_t) * 3);
      }
    }
  }
  for (const ToolDescription& t : description.tools) {
    h.text(t.name);
    h.number(t.radius_m);
    h.bytes(t.offset_device.data(), sizeof(double) * 3);
    h.number(t.finger);
    if (t.device != 0) {  // one-user scenes keep the hash they had
      h.number(t.device);
    }
  }
  for (const std::string& host : description.device_hosts) {
    h.text(host);
  }
  h.number(description.passivity_damping_factor);
  h.number(description.has_hand ? description.hand.dip_per_pip : -1.0);
  if (std::any_of(description.bodies.begin(), description.bodies.end(),
                  [](const BodyDescription& b) { return b.kind == BodyKind::kDynamic; })) {
    h.bytes(description.gravity_m_per_s2.data(), sizeof(double) * 3);
  }
  if (const auto& rig = description.teleop) {
    // What makes two rigs step differently: the slave, its start, the mapping, the ball, the sheet.
    h.number(rig->slave ? rig->slave->dof() : -1);
    for (const double q : rig->slave_start_rad) {
      h.number(q);
    }
    h.number(rig->mapping.scale);
    h.bytes(rig->mapping.X_slave_master.matrix().data(), sizeof(double) * 16);
    for (const double x :
         {rig->ball.mass_kg, rig->ball.radius_m, rig->gripper.max_force_n,
          rig->follower.gripper_max_width_m, rig->sheet.side_m, rig->force_scale}) {
      h.number(x);
    }
    h.bytes(rig->ball_start_world.data(), sizeof(double) * 3);
    h.number(rig->sheet.nodes_per_side);
    h.bytes(rig->environment.X_world_sheet.matrix().data(), sizeof(double) * 16);
  }
  char buffer[32];
  std::snprintf(buffer, sizeof buffer, "%016llx", static_cast<unsigned long long>(h.value()));
  return buffer;
}

}  // namespace hapsim
