// LOD selection by screen size (render/lod_selection.h): the projected error of a level in
// pixels picks it, with hysteresis against flipping at a boundary.
#include "hapsim/render/lod_selection.h"

#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <limits>
#include <numbers>

namespace hapsim {
namespace {

// Levels: the full mesh, then 1, 2 and 4 mm of error.
constexpr std::array<double, 4> kErrorsM = {0.0, 1e-3, 2e-3, 4e-3};

TEST(LodSelection, PixelsPerMetreIsTheViewportOverTheViewHeightAtThatDistance) {
  // tan(fov/2) = 0.5: the view is exactly d metres high at distance d.
  const double fov = 2.0 * std::atan(0.5);
  EXPECT_NEAR(pixels_per_metre(1.0, 0.01, fov, 720), 720.0, 1e-9);
  EXPECT_NEAR(pixels_per_metre(4.0, 0.01, fov, 720), 180.0, 1e-9);
  // Inside the near distance the scale stops growing (the camera's near plane).
  EXPECT_NEAR(pixels_per_metre(0.0, 0.01, fov, 720), 72000.0, 1e-6);
}

TEST(LodSelection, TheCoarsestLevelUnderTheErrorBoundIsDrawn) {
  const LodSelectionOptions o;  // 0.75 px; coarser levels only within 0.45 px
  // Far: 100 px/m, 4 mm is 0.4 px: the coarsest level.
  EXPECT_EQ(select_lod_level(kErrorsM, 100.0, 0, o), 3u);
  // 200 px/m: 4 mm is 0.8 px (too much), 2 mm is 0.4 px.
  EXPECT_EQ(select_lod_level(kErrorsM, 200.0, 0, o), 2u);
  // Near: 1000 px/m, 1 mm is a whole pixel: the full mesh.
  EXPECT_EQ(select_lod_level(kErrorsM, 1000.0, 3, o), 0u);
}

TEST(LodSelection, HysteresisKeepsTheCurrentLevelBetweenTheTwoBounds) {
  const LodSelectionOptions o;
  // 700 px/m: level 1 shows 0.7 px, under 0.75 but over 0.45.
  EXPECT_EQ(select_lod_level(kErrorsM, 700.0, 0, o), 0u);  // not coarser yet
  EXPECT_EQ(select_lod_level(kErrorsM, 700.0, 1, o), 1u);  // and kept when already there
  EXPECT_EQ(select_lod_level(kErrorsM, 700.0, 2, o), 1u);  // level 2 (1.4 px) refines at once
  // Without hysteresis level 1 is taken at once.
  EXPECT_EQ(select_lod_level(kErrorsM, 700.0, 0, {0.75, 1.0}), 1u);
}

// Zooming in never coarsens and zooming out never refines; a small jitter of the scale at a
// boundary changes the level at most once.
TEST(LodSelection, ZoomingSweepsTheLevelsMonotonicallyWithoutFlipping) {
  std::size_t level = 0;
  std::size_t previous = 0;
  for (double ppm = 50.0; ppm < 5000.0; ppm *= 1.05) {  // zooming in
    level = select_lod_level(kErrorsM, ppm, level);
    if (ppm > 50.0) {
      EXPECT_LE(level, previous) << ppm;
    }
    previous = level;
  }
  EXPECT_EQ(level, 0u);
  for (double ppm = 5000.0; ppm > 50.0; ppm /= 1.05) {  // zooming out
    level = select_lod_level(kErrorsM, ppm, level);
    EXPECT_GE(level, previous) << ppm;
    previous = level;
  }
  EXPECT_EQ(level, 3u);
  // Jitter of ±2 % about the point where level 1 reaches 0.75 px: one switch, then stable.
  level = 1;
  int switches = 0;
  for (int i = 0; i < 100; ++i) {
    const double ppm = 750.0 * (i % 2 == 0 ? 1.02 : 0.98);
    const std::size_t next = select_lod_level(kErrorsM, ppm, level);
    switches += next != level ? 1 : 0;
    level = next;
  }
  EXPECT_LE(switches, 1);
}

TEST(LodSelection, NoLevelsOrNoScaleDrawTheFullMesh) {
  EXPECT_EQ(select_lod_level({}, 100.0, 2), 0u);
  EXPECT_EQ(select_lod_level(kErrorsM, std::numeric_limits<double>::quiet_NaN(), 2), 0u);
  EXPECT_EQ(select_lod_level(kErrorsM, std::numeric_limits<double>::infinity(), 2), 0u);
  // A current level beyond the list is clamped.
  EXPECT_EQ(select_lod_level(kErrorsM, 100.0, 9), 3u);
}

}  // namespace
}  // namespace hapsim
