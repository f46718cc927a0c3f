#include "hapsim/render/lod_selection.h"

#include <algorithm>
#include <cmath>

namespace hapsim {

double pixels_per_metre(double distance_m, double near_m, double fov_y_rad,
                        int viewport_height_px) {
  const double d = std::max(distance_m, near_m);
  const double view_height_m = 2.0 * d * std::tan(0.5 * fov_y_rad);
  return view_height_m > 0.0 ? static_cast<double>(viewport_height_px) / view_height_m : 0.0;
}

std::size_t select_lod_level(std::span<const double> level_error_m, double px_per_m,
                             std::size_t current, const LodSelectionOptions& options) {
  if (level_error_m.empty()) {
    return 0;
  }
  if (!std::isfinite(px_per_m)) {
    return 0;  // no sane scale: the full mesh is always right
  }
  current = std::min(current, level_error_m.size() - 1);
  // The coarsest level within `bound_px` (level 0 always is).
  const auto coarsest_within = [&](double bound_px) {
    std::size_t level = 0;
    for (std::size_t i = 1; i < level_error_m.size(); ++i) {
      if (level_error_m[i] * px_per_m <= bound_px) {
        level = i;
      }
    }
    return level;
  };
  const std::size_t allowed = coarsest_within(options.max_error_px);
  if (allowed <= current) {
    return allowed;  // finer at once: the current level shows too much error (or just enough)
  }
  // Coarser only past the stricter bound; otherwise keep what is drawn.
  return std::max(current, coarsest_within(options.coarsen_fraction * options.max_error_px));
}

}  // namespace hapsim
