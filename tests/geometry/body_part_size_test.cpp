// The plausibility rule for a mesh's size: body parts are 1 mm to 3 m across; outside that the
// advice names the scale a unit mistake calls for (a knee in millimetres read as metres, one in
// metres read as millimetres), checked on the worked cases of the issue and at the thresholds.
#include "hapsim/geometry/body_part_size.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>

namespace hapsim {
namespace {

TEST(BodyPartSize, WithinOneMillimetreAndThreeMetresIsPlausible) {
  for (const double extent : {1e-3, 0.042, 0.47, 1.8, 3.0}) {
    SCOPED_TRACE(extent);
    EXPECT_FALSE(check_body_part_size(extent, 1.0));
    EXPECT_FALSE(check_body_part_size(extent, 0.001));
  }
}

TEST(BodyPartSize, APatellaInMillimetresReadAsMetresIsTooLarge) {
  // A 42 mm patella whose file numbers are millimetres, loaded at scale 1: 42 m.
  const auto a = check_body_part_size(42.0, 1.0);
  ASSERT_TRUE(a);
  EXPECT_TRUE(a->too_large);
  EXPECT_DOUBLE_EQ(a->extent_m, 42.0);
  EXPECT_DOUBLE_EQ(a->suggested_scale, 0.001);
  EXPECT_EQ(a->likely_mistake, "millimetres read as metres");
  EXPECT_EQ(describe(*a),
            "is 42 m across at scale 1: implausibly large for a body part (1 mm to 3 m); "
            "millimetres read as metres? Use \"scale\": 0.001");
  // Just above the limit too: 3.5 m at scale 1 is a 3.5 mm part in millimetres.
  const auto b = check_body_part_size(3.5, 1.0);
  ASSERT_TRUE(b);
  EXPECT_DOUBLE_EQ(b->suggested_scale, 0.001);
}

TEST(BodyPartSize, ABoneInMetresReadAsMillimetresIsTooSmall) {
  // A 40 mm bone whose file numbers are metres (0.04), loaded at scale 0.001: 0.04 mm.
  const auto a = check_body_part_size(0.04 * 0.001, 0.001);
  ASSERT_TRUE(a);
  EXPECT_FALSE(a->too_large);
  EXPECT_DOUBLE_EQ(a->suggested_scale, 1.0);
  EXPECT_EQ(a->likely_mistake, "metres read as millimetres");
  EXPECT_EQ(describe(*a),
            "is 0.04 mm across at scale 0.001: implausibly small for a body part (1 mm to 3 m); "
            "metres read as millimetres? Use \"scale\": 1");
  // Just below the limit: 0.9 mm at scale 0.001 is a 0.9 m thing in metres.
  const auto b = check_body_part_size(0.9e-3, 0.001);
  ASSERT_TRUE(b);
  EXPECT_DOUBLE_EQ(b->suggested_scale, 1.0);
}

TEST(BodyPartSize, CentimetresWhenMetresDoNotFitAndAPowerOfTenWhenNoUnitDoes) {
  // 0.5 mm at scale 1e-4: 5 file units; as metres 5 m (too large), as centimetres 50 mm.
  const auto cm = check_body_part_size(5e-4, 1e-4);
  ASSERT_TRUE(cm);
  EXPECT_DOUBLE_EQ(cm->suggested_scale, 0.01);
  EXPECT_EQ(cm->likely_mistake, "");  // 1e-4 is no common unit
  // 42 m already at scale 0.001 (42000 file units): no common unit fits; 1e-6 makes it 42 mm,
  // the power of ten nearest 10 cm.
  const auto p = check_body_part_size(42.0, 0.001);
  ASSERT_TRUE(p);
  EXPECT_NEAR(p->suggested_scale, 1e-6, 1e-18);
  const double fixed = 42.0 / 0.001 * p->suggested_scale;
  EXPECT_GE(fixed, kBodyPartMinExtentM);
  EXPECT_LE(fixed, kBodyPartMaxExtentM);
  EXPECT_EQ(describe(*p),
            "is 42 m across at scale 0.001: implausibly large for a body part (1 mm to 3 m); "
            "use \"scale\": 1e-06");
}

TEST(BodyPartSize, EverySuggestionLandsInRange) {
  for (const double scale : {1e-4, 1e-3, 1e-2, 1.0, 25.4}) {
    for (double extent = 1e-7; extent < 1e5; extent *= 1.7) {
      const auto a = check_body_part_size(extent, scale);
      if (!a) {
        EXPECT_GE(extent, kBodyPartMinExtentM);
        EXPECT_LE(extent, kBodyPartMaxExtentM);
        continue;
      }
      const double fixed = extent / scale * a->suggested_scale;
      EXPECT_GE(fixed, kBodyPartMinExtentM * 0.999) << extent << " at " << scale;
      EXPECT_LE(fixed, kBodyPartMaxExtentM * 1.001) << extent << " at " << scale;
    }
  }
}

TEST(BodyPartSize, DegenerateNumbersAreLeftToValidation) {
  EXPECT_FALSE(check_body_part_size(0.0, 1.0));
  EXPECT_FALSE(check_body_part_size(std::numeric_limits<double>::quiet_NaN(), 1.0));
  EXPECT_FALSE(check_body_part_size(std::numeric_limits<double>::infinity(), 1.0));
  EXPECT_FALSE(check_body_part_size(42.0, 0.0));
}

}  // namespace
}  // namespace hapsim
