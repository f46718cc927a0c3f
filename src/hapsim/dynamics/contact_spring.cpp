#include "hapsim/dynamics/contact_spring.h"

#include <algorithm>
#include <cmath>

namespace hapsim {

Vec3 contact_spring_force(const ContactSpring& spring, double penetration_m, const Vec3& normal,
                          const Vec3& v_rel, const Vec3& p_body, FrictionAnchor& anchor) noexcept {
  if (!(penetration_m > 0.0) || !std::isfinite(penetration_m) || !normal.allFinite() ||
      !v_rel.allFinite() || !p_body.allFinite()) {
    anchor.active = false;
    return Vec3::Zero();
  }
  const double v_n = v_rel.dot(normal);
  // Damping only while it adds to the push: a spring-damper may not pull the body back in.
  const double f_n =
      std::max(0.0, spring.stiffness_n_per_m * penetration_m - spring.damping_n_s_per_m * v_n);
  if (!anchor.active) {
    anchor = {true, p_body};
  }
  const auto tangential = [&](const Vec3& v) { return Vec3(v - v.dot(normal) * normal); };
  const Vec3 stretch_t = tangential(p_body - anchor.p_world);
  Vec3 f_t = -spring.friction_stiffness_n_per_m * stretch_t -
             spring.friction_damping_n_s_per_m * tangential(v_rel);
  const double cap = spring.friction * f_n;
  const double f_t_norm = f_t.norm();
  if (f_t_norm > cap) {
    // Slipping: the force is μ·N against the motion, and the anchor follows so the spring holds
    // exactly that much.
    f_t *= f_t_norm > 0.0 ? cap / f_t_norm : 0.0;
    anchor.p_world = spring.friction_stiffness_n_per_m > 0.0
                         ? Vec3(p_body + f_t / spring.friction_stiffness_n_per_m)
                         : p_body;
  }
  return f_n * normal + f_t;
}

}  // namespace hapsim
