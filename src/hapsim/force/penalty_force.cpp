#include "hapsim/force/penalty_force.h"

#include <algorithm>
#include <cmath>

namespace hapsim {

double penalty_force_magnitude(const ContactMaterial& material, double depth_m,
                               double approach_speed_m_per_s) {
  if (!std::isfinite(depth_m) || !(depth_m > 0.0)) {
    return 0.0;
  }
  const double x = std::min(depth_m, material.max_penetration_m);
  double force = material.stiffness_n_per_m * x;
  if (std::isfinite(approach_speed_m_per_s)) {
    force += material.damping_n_s_per_m * approach_speed_m_per_s;
  }
  // Damping may pull back while separating, but a contact never pulls the tool in.
  force = std::clamp(force, 0.0, material.max_force_n);
  return std::isfinite(force) ? force : 0.0;
}

Vec3 penalty_force(const ContactMaterial& material, double depth_m, const Vec3& n_world,
                   double approach_speed_m_per_s) {
  const double magnitude = penalty_force_magnitude(material, depth_m, approach_speed_m_per_s);
  if (magnitude == 0.0 || !n_world.allFinite()) {
    return Vec3::Zero();
  }
  const double len = n_world.norm();
  return len > 0.0 ? Vec3(n_world * (magnitude / len)) : Vec3::Zero();
}

}  // namespace hapsim
