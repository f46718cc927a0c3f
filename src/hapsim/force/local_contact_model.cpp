#include "hapsim/force/local_contact_model.h"

#include <cmath>

namespace hapsim {

double series_stiffness_n_per_m(double contact_stiffness_n_per_m,
                                double tissue_stiffness_n_per_m) noexcept {
  if (!(contact_stiffness_n_per_m > 0.0) || !(tissue_stiffness_n_per_m > 0.0) ||
      std::isinf(contact_stiffness_n_per_m)) {
    return 0.0;
  }
  if (std::isinf(tissue_stiffness_n_per_m)) {
    return contact_stiffness_n_per_m;
  }
  return contact_stiffness_n_per_m * tissue_stiffness_n_per_m /
         (contact_stiffness_n_per_m + tissue_stiffness_n_per_m);
}

// haptic path
Vec3 local_model_force(const LocalContactModel& model, const Vec3& x_world_m,
                       const Vec3& v_world_m_per_s) noexcept {
  if (!model.valid) {
    return Vec3::Zero();
  }
  const Vec3 f = model.f0_world_n - model.stiffness_n_per_m * (x_world_m - model.x0_world_m) -
                 model.damping_n_s_per_m * (v_world_m_per_s - model.v0_world_m_per_s);
  return f.allFinite() ? f : Vec3::Zero();
}

double tissue_coupled_force_n(double rendered_force_n, double compression_m,
                              double contact_stiffness_n_per_m,
                              double model_stiffness_n_per_m) noexcept {
  if (!(contact_stiffness_n_per_m > 0.0)) {
    return 0.0;
  }
  const double f0 =
      rendered_force_n +
      model_stiffness_n_per_m * (compression_m - rendered_force_n / contact_stiffness_n_per_m);
  return std::isfinite(f0) ? f0 : 0.0;
}

}  // namespace hapsim
