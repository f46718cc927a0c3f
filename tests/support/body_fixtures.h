// Bodies and materials the world tests of dynamic bodies share: a penalty material with Coulomb
// friction, a static floor box whose top face is z = 0, a Gaussian sheet, a probe input.
#pragma once

#include "hapsim/geometry/procedural.h"
#include "hapsim/world/world_description.h"

namespace hapsim::test {

/// A penalty material: stiffness k (N/m), force cap (N), one friction coefficient for static
/// and dynamic, 10 mm depth cap.
inline MaterialDescription penalty_material(const char* name, double k, double max_force_n,
                                            double friction) {
  MaterialDescription m;
  m.name = name;
  m.response = ContactResponse::kPenalty;
  m.contact.stiffness_n_per_m = k;
  m.contact.max_penetration_m = 0.01;
  m.contact.max_force_n = max_force_n;
  m.contact.static_friction = friction;
  m.contact.dynamic_friction = friction;
  return m;
}

/// A static floor box, 0.6 m square and 0.1 m thick, whose top face is z = 0.
inline BodyDescription floor_body(std::uint32_t material) {
  BodyDescription b;
  b.name = "floor";
  b.X_world_body = Iso3(Eigen::Translation3d(0.0, 0.0, -0.05));
  SegmentDescription s;
  s.name = "floor";
  s.material = material;
  s.mesh = make_box(Vec3(0.3, 0.3, 0.05));
  b.segments.push_back(std::move(s));
  return b;
}

/// A Gaussian sheet (two-sided, its default grid and side) at z = 0 of the world.
inline BodyDescription sheet_body(std::uint32_t material) {
  BodyDescription b;
  b.name = "sheet";
  b.kind = BodyKind::kDeformable;
  b.deformation = BodyDeformation::kGaussianSheet;
  SegmentDescription s;
  s.name = "sheet";
  s.material = material;
  s.mesh = make_sheet(b.sheet.nodes_per_side, b.sheet.side_m);
  s.two_sided = true;
  b.segments.push_back(std::move(s));
  return b;
}

/// A device input with the probe at p_world.
inline DeviceInput probe_at(const Vec3& p_world) {
  DeviceInput in;
  in.p_world = p_world;
  return in;
}

}  // namespace hapsim::test
