// The passivity floor (world/passivity_floor.h): factor · k · T, Colgate & Schenkel's b > k·T/2
// scaled by the scene's factor, and nothing for a period that is not one.
#include "hapsim/world/passivity_floor.h"

#include <limits>

#include <gtest/gtest.h>

namespace hapsim {
namespace {

TEST(PassivityFloor, IsTheFactorTimesTheStiffnessTimesThePeriod) {
  EXPECT_DOUBLE_EQ(passivity_damping_floor_n_s_per_m(1.0, 3000.0, 1e-3), 3.0);
  EXPECT_DOUBLE_EQ(passivity_damping_floor_n_s_per_m(0.5, 3000.0, 1e-3), 1.5);   // Colgate's k·T/2
  EXPECT_DOUBLE_EQ(passivity_damping_floor_n_s_per_m(1.0, 3000.0, 0.01), 30.0);  // a FEM period
}

TEST(PassivityFloor, IsZeroForAPeriodThatIsNotOne) {
  EXPECT_EQ(passivity_damping_floor_n_s_per_m(1.0, 3000.0, 0.0), 0.0);
  EXPECT_EQ(passivity_damping_floor_n_s_per_m(1.0, 3000.0, -1e-3), 0.0);
  EXPECT_EQ(
      passivity_damping_floor_n_s_per_m(1.0, 3000.0, std::numeric_limits<double>::quiet_NaN()),
      0.0);
  EXPECT_EQ(passivity_damping_floor_n_s_per_m(1.0, 3000.0, std::numeric_limits<double>::infinity()),
            0.0);
}

}  // namespace
}  // namespace hapsim
