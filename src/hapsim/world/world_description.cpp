#include "hapsim/world/world_description.h"

#include "hapsim/world/content_fingerprint.h"

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

std::string content_hash(const WorldDescription& description) {
  ContentFingerprint h;
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
  if (description.controller) {
    description.controller->fingerprint(h);
  }
  char buffer[32];
  std::snprintf(buffer, sizeof buffer, "%016llx", static_cast<unsigned long long>(h.value()));
  return buffer;
}

}  // namespace hapsim
