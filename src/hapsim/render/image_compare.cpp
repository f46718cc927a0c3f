#include "hapsim/render/image_compare.h"

#include <algorithm>
#include <cstdlib>
#include <sstream>

namespace hapsim {

double ImageDiff::worst_mean_abs_diff() const {
  return *std::max_element(mean_abs_diff.begin(), mean_abs_diff.end());
}

bool ImageDiff::within(const ImageTolerance& tolerance) const {
  return same_size && worst_mean_abs_diff() <= tolerance.max_mean_abs_diff &&
         differing_fraction <= tolerance.max_differing_fraction;
}

std::string ImageDiff::describe() const {
  std::ostringstream os;
  if (!same_size) {
    os << "image sizes differ (expected " << width << "x" << height << " RGBA)";
    return os.str();
  }
  os.precision(3);
  os << width << "x" << height << ", mean |diff| R " << mean_abs_diff[0] << " G "
     << mean_abs_diff[1] << " B " << mean_abs_diff[2] << " A " << mean_abs_diff[3] << ", max "
     << max_abs_diff << ", " << 100.0 * differing_fraction << "% of pixels differ by > "
     << pixel_threshold;
  return os.str();
}

ImageDiff compare_images(std::span<const std::uint8_t> a, std::span<const std::uint8_t> b,
                         int width, int height, int pixel_threshold) {
  ImageDiff diff;
  diff.width = width;
  diff.height = height;
  diff.pixel_threshold = pixel_threshold;
  const std::size_t pixels =
      width > 0 && height > 0 ? static_cast<std::size_t>(width) * static_cast<std::size_t>(height)
                              : 0;
  diff.same_size = pixels > 0 && a.size() == pixels * 4 && b.size() == pixels * 4;
  if (!diff.same_size) {
    return diff;
  }
  std::array<std::uint64_t, 4> sums{};
  std::size_t differing = 0;
  for (std::size_t p = 0; p < pixels; ++p) {
    int pixel_max = 0;
    for (std::size_t c = 0; c < 4; ++c) {
      const int d = std::abs(int{a[4 * p + c]} - int{b[4 * p + c]});
      sums[c] += static_cast<std::uint64_t>(d);
      pixel_max = std::max(pixel_max, d);
    }
    diff.max_abs_diff = std::max(diff.max_abs_diff, pixel_max);
    if (pixel_max > pixel_threshold) {
      ++differing;
    }
  }
  for (std::size_t c = 0; c < 4; ++c) {
    diff.mean_abs_diff[c] = static_cast<double>(sums[c]) / static_cast<double>(pixels);
  }
  diff.differing_fraction = static_cast<double>(differing) / static_cast<double>(pixels);
  return diff;
}

}  // namespace hapsim
