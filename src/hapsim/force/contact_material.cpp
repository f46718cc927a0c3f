#include "hapsim/force/contact_material.h"

#include <algorithm>
#include <cmath>

namespace hapsim {

namespace {

// 1/(1/x + 1/y): an infinitely stiff side gives the other, and nothing overflows.
double in_series(double x, double y) noexcept {
  return x > 0.0 && y > 0.0 ? 1.0 / (1.0 / x + 1.0 / y) : 0.0;
}

}  // namespace

ContactMaterial combine_materials(const ContactMaterial& a, const ContactMaterial& b) noexcept {
  ContactMaterial m;
  m.stiffness_n_per_m = in_series(a.stiffness_n_per_m, b.stiffness_n_per_m);
  m.damping_n_s_per_m = in_series(a.damping_n_s_per_m, b.damping_n_s_per_m);
  m.max_penetration_m = a.max_penetration_m + b.max_penetration_m;
  m.max_force_n = std::min(a.max_force_n, b.max_force_n);
  m.static_friction = std::max(a.static_friction, b.static_friction);
  m.dynamic_friction = std::max(a.dynamic_friction, b.dynamic_friction);
  return m;
}

}  // namespace hapsim
