#include "hapsim/force/penalty_force.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>

namespace hapsim {
namespace {

ContactMaterial soft_tissue() {
  ContactMaterial m;
  m.stiffness_n_per_m = 300.0;
  m.max_penetration_m = 0.010;
  m.max_force_n = 2.0;
  return m;
}

ContactMaterial bone() {
  ContactMaterial m;
  m.stiffness_n_per_m = 5000.0;
  m.max_penetration_m = 0.0005;
  m.max_force_n = 20.0;
  return m;
}

TEST(PenaltyForce, HookesLawBelowTheLimits) {
  EXPECT_DOUBLE_EQ(penalty_force_magnitude(soft_tissue(), 0.004), 300.0 * 0.004);
  EXPECT_DOUBLE_EQ(penalty_force_magnitude(bone(), 0.0002), 5000.0 * 0.0002);
}

TEST(PenaltyForce, SaturatesAtMaximumPenetrationAndForce) {
  // Bone: 0.5 mm max penetration -> 2.5 N however deep the probe goes.
  EXPECT_DOUBLE_EQ(penalty_force_magnitude(bone(), 0.003), 5000.0 * 0.0005);
  // Soft tissue: force capped at 2 N before the penetration cap (300 N/m * 10 mm = 3 N).
  EXPECT_DOUBLE_EQ(penalty_force_magnitude(soft_tissue(), 0.009), 2.0);
}

TEST(PenaltyForce, NeverPullsNeverNaN) {
  const double nan = std::numeric_limits<double>::quiet_NaN();
  const double inf = std::numeric_limits<double>::infinity();
  ContactMaterial m = soft_tissue();
  m.damping_n_s_per_m = 50.0;
  EXPECT_EQ(penalty_force_magnitude(m, -0.001), 0.0);  // not touching
  EXPECT_EQ(penalty_force_magnitude(m, nan), 0.0);
  EXPECT_EQ(penalty_force_magnitude(m, inf), 0.0);
  EXPECT_EQ(penalty_force_magnitude(m, 0.001, nan), 300.0 * 0.001);  // bad speed: spring only
  EXPECT_EQ(penalty_force_magnitude(m, 0.001, -10.0), 0.0);  // fast release: no pulling
  EXPECT_EQ(penalty_force(m, 0.001, Vec3(nan, 0, 0)), Vec3::Zero());
}

TEST(PenaltyForce, DampingOpposesApproach) {
  ContactMaterial m = soft_tissue();
  m.damping_n_s_per_m = 10.0;
  EXPECT_DOUBLE_EQ(penalty_force_magnitude(m, 0.001, 0.05), 0.3 + 0.5);
  EXPECT_DOUBLE_EQ(penalty_force_magnitude(m, 0.001, -0.01), 0.3 - 0.1);
}

TEST(PenaltyForce, VectorAlongNormal) {
  const Vec3 f = penalty_force(soft_tissue(), 0.002, Vec3(0, 0, 2.0));  // normal not unit
  EXPECT_NEAR(f.x(), 0.0, 1e-15);
  EXPECT_NEAR(f.z(), 0.6, 1e-12);
}

}  // namespace
}  // namespace hapsim
