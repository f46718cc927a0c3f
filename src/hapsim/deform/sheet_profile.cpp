#include "hapsim/deform/sheet_profile.h"

#include "hapsim/core/error.h"

#include <cmath>
#include <string>

namespace hapsim {

namespace {

void require_positive(double value, const char* name) {
  if (!std::isfinite(value) || value <= 0.0) {
    throw Error(std::string("GaussianSheetParams.") + name,
                "expected a finite value > 0, got " + std::to_string(value));
  }
}

}  // namespace

GaussianSheetProfile::GaussianSheetProfile(GaussianSheetParams params) : params_(params) {
  require_positive(params_.cutoff_radius_m, "cutoff_radius_m");
  require_positive(params_.width_m, "width_m");
  require_positive(params_.sensitivity_n_per_m, "sensitivity_n_per_m");
  inv_width_sq_per_m2_ = 1.0 / (params_.width_m * params_.width_m);
  tail_ = std::exp(-params_.cutoff_radius_m * params_.cutoff_radius_m * inv_width_sq_per_m2_);
}

// haptic path
double GaussianSheetProfile::depth_m(double distance_m, double force_n) const {
  if (!(distance_m < params_.cutoff_radius_m)) {
    return 0.0;
  }
  const double shape = std::exp(-distance_m * distance_m * inv_width_sq_per_m2_) - tail_;
  return force_n / params_.sensitivity_n_per_m * shape;
}

}  // namespace hapsim
