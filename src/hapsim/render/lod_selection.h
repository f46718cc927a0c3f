// Which level of detail to draw (issue 13 item 2): the coarsest whose error, projected to the
// screen where the mesh comes nearest the eye, stays under a fraction of a pixel. A level that
// would be coarser than the one drawn must clear a stricter bound before the switch (hysteresis),
// so a mesh at the boundary does not flip between levels from frame to frame.
#pragma once

#include <cstddef>
#include <span>

namespace hapsim {

struct LodSelectionOptions {
  /// Largest error a drawn level may show on screen, pixels.
  double max_error_px = 0.75;
  /// A coarser level than the current one is taken only when its error is within this fraction
  /// of max_error_px (1: no hysteresis).
  double coarsen_fraction = 0.6;
};

/// Pixels per metre at `distance_m` from the eye, for a perspective view `fov_y_rad` high over a
/// viewport `viewport_height_px` tall. A distance at or below `near_m` counts as `near_m`.
[[nodiscard]] double pixels_per_metre(double distance_m, double near_m, double fov_y_rad,
                                      int viewport_height_px);

/// The level to draw: `level_error_m[i]` is level i's error in metres, level 0 the full mesh
/// (error 0) and errors non-decreasing; `px_per_m` the scale where the mesh is nearest the eye
/// (pixels_per_metre); `current` the level drawn last frame. Returns an index into
/// `level_error_m` (0 for an empty list).
[[nodiscard]] std::size_t select_lod_level(std::span<const double> level_error_m, double px_per_m,
                                           std::size_t current,
                                           const LodSelectionOptions& options = {});

}  // namespace hapsim
