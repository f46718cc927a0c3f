#include "hapsim/force/local_contact_model.h"

#include <algorithm>
#include <cmath>
#include <limits>

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
  const Vec3 spring_n = model.f0_world_n - model.stiffness_n_per_m * (x_world_m - model.x0_world_m);
  Vec3 f = spring_n - model.damping_n_s_per_m * (v_world_m_per_s - model.v0_world_m_per_s);
  if (model.profile_count >= 2 && !model.normal_world.isZero()) {
    // Along the normal, the profile's push at this depth instead of the linear spring's.
    const double depth_m = -(x_world_m - model.x0_world_m).dot(model.normal_world);
    f += (profile_push_n(model, depth_m) - spring_n.dot(model.normal_world)) * model.normal_world;
  }
  return f.allFinite() ? f : Vec3::Zero();
}

// haptic path
double profile_push_n(const LocalContactModel& model, double depth_m) noexcept {
  const int n = std::min(model.profile_count, LocalContactModel::kMaxProfilePoints);
  if (n < 2) {
    return std::numeric_limits<double>::quiet_NaN();
  }
  const auto& d = model.profile_depth_m;
  const auto& p = model.profile_push_n;
  // The segment holding depth_m; the first or last one beyond the ends.
  int i = 0;
  while (i + 2 < n && depth_m > d[static_cast<std::size_t>(i + 1)]) {
    ++i;
  }
  const auto a = static_cast<std::size_t>(i);
  const double span_m = d[a + 1] - d[a];
  const double slope = span_m > 0.0 ? (p[a + 1] - p[a]) / span_m : 0.0;
  return p[a] + slope * (depth_m - d[a]);
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
