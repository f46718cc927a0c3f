// The runtime tests' small world: a stiff "bone" block (proxy) with its top face at z = 0, and a
// soft deformable "muscle" sphere (penalty, k = 300 N/m, radius 30 mm, top at z = 0) beside it at
// x = 0.2, one 4 mm tool.
#pragma once

#include "hapsim/geometry/procedural.h"
#include "hapsim/world/world_description.h"

#include <utility>

namespace hapsim::test {

inline MaterialDescription material(const char* name, ContactResponse response, double k,
                                    double max_force_n) {
  MaterialDescription m;
  m.name = name;
  m.response = response;
  m.contact.stiffness_n_per_m = k;
  m.contact.max_penetration_m = 0.02;
  m.contact.max_force_n = max_force_n;
  return m;
}

// A stiff "bone" block (proxy) with its top face at z = 0, and a soft deformable "muscle" sphere
// beside it at x = 0.2, resting on nothing.
inline WorldDescription two_body_world() {
  WorldDescription w;
  w.name = "session-test";
  w.materials.push_back(material("bone", ContactResponse::kProxy, 3000.0, 40.0));
  w.materials.push_back(material("muscle", ContactResponse::kPenalty, 300.0, 2.0));
  BodyDescription bone;
  bone.name = "bone";
  bone.X_world_body = Iso3(Eigen::Translation3d(0, 0, -0.02));
  SegmentDescription block;
  block.name = "block";
  block.material = 0;
  block.mesh = make_box(Vec3(0.05, 0.05, 0.02));
  bone.segments.push_back(std::move(block));
  w.bodies.push_back(std::move(bone));
  BodyDescription soft;
  soft.name = "soft";
  soft.kind = BodyKind::kDeformable;
  soft.X_world_body = Iso3(Eigen::Translation3d(0.2, 0, -0.03));
  SegmentDescription ball;
  ball.name = "ball";
  ball.material = 1;
  ball.mesh = make_uv_sphere(0.03, 48, 24);
  soft.segments.push_back(std::move(ball));
  w.bodies.push_back(std::move(soft));
  ToolDescription tip;
  tip.name = "tip";
  tip.radius_m = 0.004;
  w.tools.push_back(tip);
  return w;
}

}  // namespace hapsim::test
