// compare_images: zero for identical images, over a tight tolerance for shifted or brightened ones.
#include "hapsim/render/image_compare.h"

#include <gtest/gtest.h>

#include <vector>

namespace hapsim {
namespace {

constexpr int kW = 64;
constexpr int kH = 48;

// A smooth gradient with a bright square: shifting it changes the square's edges.
std::vector<std::uint8_t> make_image(int shift_x = 0, int brighten = 0) {
  std::vector<std::uint8_t> rgba(kW * kH * 4);
  for (int y = 0; y < kH; ++y) {
    for (int x = 0; x < kW; ++x) {
      const int xs = x - shift_x;
      const bool square = xs >= 20 && xs < 40 && y >= 10 && y < 30;
      const std::size_t i = 4 * static_cast<std::size_t>(y * kW + x);
      rgba[i + 0] = static_cast<std::uint8_t>(std::min(255, (square ? 230 : 2 * y) + brighten));
      rgba[i + 1] = static_cast<std::uint8_t>(std::min(255, (square ? 200 : 3 * x) + brighten));
      rgba[i + 2] = static_cast<std::uint8_t>(std::min(255, 60 + brighten));
      rgba[i + 3] = 255;
    }
  }
  return rgba;
}

TEST(ImageCompare, IdenticalImagesDifferByNothing) {
  const auto a = make_image();
  const ImageDiff d = compare_images(a, a, kW, kH);
  EXPECT_TRUE(d.same_size);
  EXPECT_EQ(d.max_abs_diff, 0);
  EXPECT_EQ(d.worst_mean_abs_diff(), 0.0);
  EXPECT_EQ(d.differing_fraction, 0.0);
  EXPECT_TRUE(d.within(ImageTolerance{0.0, 0.0}));
}

TEST(ImageCompare, ShiftedImageExceedsATightTolerance) {
  const ImageDiff d = compare_images(make_image(), make_image(3), kW, kH);
  // The square's two vertical edges move 3 px: 2·3·20 pixels change strongly, plus the gradient.
  EXPECT_GE(d.differing_fraction, 2.0 * 3 * 20 / (kW * kH) - 1e-12);
  EXPECT_FALSE(d.within(ImageTolerance{1.0, 0.01})) << d.describe();
}

TEST(ImageCompare, BrightenedImageIsMeasuredPerChannel) {
  const ImageDiff d = compare_images(make_image(), make_image(0, 5), kW, kH);
  // Every unsaturated channel +5 levels; alpha untouched.
  EXPECT_NEAR(d.mean_abs_diff[2], 5.0, 1e-12);
  EXPECT_EQ(d.mean_abs_diff[3], 0.0);
  EXPECT_EQ(d.max_abs_diff, 5);
  EXPECT_EQ(d.differing_fraction, 0.0);  // 5 ≤ the default 8-level pixel threshold
  EXPECT_FALSE(d.within(ImageTolerance{2.0, 0.01})) << d.describe();
  EXPECT_TRUE(d.within(ImageTolerance{5.0, 0.0})) << d.describe();
  EXPECT_NE(d.describe().find("64x48"), std::string::npos);
}

TEST(ImageCompare, SizeMismatchIsNeverWithin) {
  const auto a = make_image();
  const std::vector<std::uint8_t> b(a.begin(), a.end() - 4);
  const ImageDiff d = compare_images(a, b, kW, kH);
  EXPECT_FALSE(d.same_size);
  EXPECT_FALSE(d.within(ImageTolerance{255.0, 1.0}));
}

}  // namespace
}  // namespace hapsim
