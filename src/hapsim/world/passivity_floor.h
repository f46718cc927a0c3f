// The one rule for the least damping a sampled contact spring needs: a spring of stiffness k
// sampled at period T is active (Colgate & Schenkel 1997), and b > k·T/2 makes it passive again;
// the scene's passivity_damping_factor (default 1) scales k·T, giving margin. Used for the
// device's materials, the contacts between bodies and a FEM body's own sampling period.
#pragma once

#include <cmath>

namespace hapsim {

/// factor · k · T in N·s/m; 0 when T is not finite and > 0.
[[nodiscard]] inline double passivity_damping_floor_n_s_per_m(double factor,
                                                              double stiffness_n_per_m,
                                                              double period_s) noexcept {
  const double t = std::isfinite(period_s) && period_s > 0.0 ? period_s : 0.0;
  return factor * stiffness_n_per_m * t;
}

}  // namespace hapsim
