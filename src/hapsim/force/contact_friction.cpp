#include "hapsim/force/contact_friction.h"

#include <cmath>

namespace hapsim {

// haptic path
Vec3 contact_friction_force(const ContactMaterial& material, double normal_force_n,
                            const Vec3& n_world, const Vec3& v_rel_world,
                            const Vec3& p_contact_world, StickPoint& stick_world) noexcept {
  const double k = material.stiffness_n_per_m;
  if (!(normal_force_n > 0.0) || !(material.static_friction > 0.0) || !(k > 0.0) ||
      !std::isfinite(normal_force_n) || !n_world.allFinite() || !v_rel_world.allFinite() ||
      !p_contact_world.allFinite()) {
    stick_world.active = false;
    return Vec3::Zero();
  }
  if (!stick_world.active) {
    stick_world = {true, p_contact_world};
  }
  const auto tangential = [&](const Vec3& v) { return Vec3(v - v.dot(n_world) * n_world); };
  Vec3 f = -k * tangential(p_contact_world - stick_world.p) -
           material.damping_n_s_per_m * tangential(v_rel_world);
  const double f_norm = f.norm();
  if (f_norm > material.static_friction * normal_force_n) {
    // Slipping: μd·N against the stretch, and the stick point follows.
    f *= material.dynamic_friction * normal_force_n / f_norm;
    stick_world.p = p_contact_world + f / k;
  }
  return f;
}

}  // namespace hapsim
