// Tolerance-based comparison of RGBA images for reference-image tests: a software rasteriser's
// output moves by a few levels between Mesa versions, so tests bound the differences instead of
// demanding equal bytes.
#pragma once

#include <array>
#include <cstdint>
#include <span>
#include <string>

namespace hapsim {

struct ImageTolerance {
  /// Largest allowed mean absolute difference of any channel, in levels (0–255).
  double max_mean_abs_diff = 2.0;
  /// Largest allowed fraction of pixels counted as different (see ImageDiff).
  double max_differing_fraction = 0.01;
};

struct ImageDiff {
  bool same_size = false;
  int width = 0;
  int height = 0;
  /// Mean |a − b| per channel (R, G, B, A), levels.
  std::array<double, 4> mean_abs_diff{};
  /// Largest |a − b| of any channel of any pixel, levels.
  int max_abs_diff = 0;
  /// Fraction of pixels whose largest channel difference exceeds the pixel threshold.
  double differing_fraction = 0.0;
  int pixel_threshold = 0;

  [[nodiscard]] double worst_mean_abs_diff() const;
  [[nodiscard]] bool within(const ImageTolerance& tolerance) const;
  /// E.g. "320x240, mean |diff| R 0.41 G 0.40 B 0.52 A 0, max 12, 0.31% of pixels differ by > 8".
  [[nodiscard]] std::string describe() const;
};

/// Compares two width×height RGBA8 images (top row first). A pixel differs when any channel
/// differs by more than `pixel_threshold` levels. Sizes that do not match give same_size = false
/// (and within() false).
ImageDiff compare_images(std::span<const std::uint8_t> a, std::span<const std::uint8_t> b,
                         int width, int height, int pixel_threshold = 8);

}  // namespace hapsim
