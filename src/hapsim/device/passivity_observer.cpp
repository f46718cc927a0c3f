#include "hapsim/device/passivity_observer.h"

#include "hapsim/core/error.h"

#include <cmath>
#include <string>

namespace hapsim {

PassivityObserver::PassivityObserver(PassivityObserverOptions options) : options_(options) {
  if (!(std::isfinite(options_.max_damping_n_s_per_m) && options_.max_damping_n_s_per_m >= 0.0)) {
    throw Error("passivity observer", "max_damping_n_s_per_m must be finite and >= 0, got " +
                                          std::to_string(options_.max_damping_n_s_per_m));
  }
  if (!(std::isfinite(options_.energy_tolerance_j) && options_.energy_tolerance_j >= 0.0)) {
    throw Error("passivity observer", "energy_tolerance_j must be finite and >= 0, got " +
                                          std::to_string(options_.energy_tolerance_j));
  }
}

// haptic path
Vec3 PassivityObserver::filter(const Vec3& f_n, const Vec3& v_m_per_s, double dt_s) noexcept {
  ++counts_.cycles;
  if (!f_n.allFinite() || !v_m_per_s.allFinite() || !std::isfinite(dt_s) || !(dt_s > 0.0)) {
    ++counts_.nonfinite;
    return Vec3::Zero();
  }
  // What the environment will have absorbed if f goes out unchanged this cycle.
  const double energy_j = energy_j_ - f_n.dot(v_m_per_s) * dt_s;
  if (!std::isfinite(energy_j)) {
    // Finite but absurd inputs (f·v overflowed): nothing sensible to send.
    ++counts_.nonfinite;
    return Vec3::Zero();
  }
  const double speed_sq = v_m_per_s.squaredNorm();
  if (!options_.enabled || !(energy_j < -options_.energy_tolerance_j) || !(speed_sq > 0.0)) {
    energy_j_ = energy_j;
    return f_n;
  }
  // The damper that dissipates the whole deficit this cycle, within the device's rating. A
  // division by an underflowed |v|²·dt gives +inf, which the bound catches.
  double alpha_n_s_per_m = -energy_j / (speed_sq * dt_s);
  if (!(alpha_n_s_per_m <= options_.max_damping_n_s_per_m)) {
    alpha_n_s_per_m = options_.max_damping_n_s_per_m;
    ++counts_.saturated;
  }
  ++counts_.acted;
  const double dissipated_j = alpha_n_s_per_m * speed_sq * dt_s;
  counts_.dissipated_j += dissipated_j;
  energy_j_ = energy_j + dissipated_j;
  return f_n - alpha_n_s_per_m * v_m_per_s;
}

}  // namespace hapsim
