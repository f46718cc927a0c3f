// The haptic thread's own resume ceiling, on injected times (no clock, no thread): a gap since the
// previous write beyond the grace restarts the force from the supervisor's ramp gain for that gap
// (zero after a freeze) and it comes back one ramp step a cycle, whatever another thread did.
#include "hapsim/device/resume_ceiling.h"

#include <gtest/gtest.h>

#include <limits>
#include <vector>

namespace hapsim {
namespace {

constexpr double kPeriodS = 0.001;

// Ceilings of writes at `times_s` with no other thread's ceiling and no soft start.
std::vector<double> ceilings_at(const std::vector<double>& times_s, ResumeCeiling& ceiling) {
  std::vector<double> out;
  for (const double t : times_s) {
    out.push_back(ceiling.update(t, 1.0, false));
  }
  return out;
}

TEST(ResumeCeiling, OnTimeCyclesAndLateOnesWithinTheGraceKeepFullForce) {
  ResumeCeiling ceiling(kPeriodS, ForceRampParams{});  // 2 ms grace, 8 ms ramp
  // Every ms, then one 2 ms period (a late cycle): never cut.
  for (const double c : ceilings_at({0.000, 0.001, 0.002, 0.004, 0.005}, ceiling)) {
    EXPECT_EQ(c, 1.0);
  }
  EXPECT_EQ(ceiling.gaps(), 0u);
  EXPECT_FALSE(ceiling.gap_cut());
}

// The freeze of issue 14: 50 ms with no write, and no supervisor ceiling at all (it had not run
// yet): the first write after it is zero, then one ramp step (period / ramp = 1/8) a cycle.
TEST(ResumeCeiling, AFreezeRestartsFromZeroAndRampsBackWithoutTheSupervisor) {
  ResumeCeiling ceiling(kPeriodS, ForceRampParams{});
  (void)ceilings_at({0.000, 0.001, 0.002}, ceiling);
  EXPECT_EQ(ceiling.update(0.052, 1.0, false), 0.0);
  EXPECT_TRUE(ceiling.gap_cut());
  EXPECT_NEAR(ceiling.last_gap_s(), 0.050, 1e-12);
  for (int k = 1; k <= 8; ++k) {
    EXPECT_NEAR(ceiling.update(0.052 + 0.001 * k, 1.0, false), k / 8.0, 1e-12) << k;
    EXPECT_FALSE(ceiling.gap_cut());
  }
  EXPECT_EQ(ceiling.update(0.061, 1.0, false), 1.0);
  EXPECT_EQ(ceiling.gaps(), 1u);
}

// A gap inside the ramp (5 ms: 3 ms past the 2 ms grace) cuts to the supervisor's gain for it,
// 1 - 3/8, and the force comes back from there.
TEST(ResumeCeiling, AShorterGapCutsToTheSupervisorsGainForIt) {
  ResumeCeiling ceiling(kPeriodS, ForceRampParams{});
  (void)ceilings_at({0.000, 0.001}, ceiling);
  EXPECT_NEAR(ceiling.update(0.006, 1.0, false), 1.0 - 3.0 / 8.0, 1e-12);
  EXPECT_NEAR(ceiling.update(0.007, 1.0, false), 1.0 - 2.0 / 8.0, 1e-12);
}

// The supervisor's ceiling and a soft start still count (as before the gap was measured here), and
// the lower of the gap's and the supervisor's wins.
TEST(ResumeCeiling, SupervisorCeilingAndSoftStartStillCount) {
  ResumeCeiling ceiling(kPeriodS, ForceRampParams{});
  (void)ceilings_at({0.000, 0.001}, ceiling);
  EXPECT_EQ(ceiling.update(0.002, 0.25, false), 0.25);  // the supervisor ramped to a quarter
  EXPECT_NEAR(ceiling.update(0.003, 1.0, false), 0.375, 1e-12);
  EXPECT_NEAR(ceiling.update(0.004, 1.0, true), 1.0 / 8.0, 1e-12);  // soft start: one step up
  EXPECT_EQ(ceiling.update(0.0045, std::numeric_limits<double>::quiet_NaN(), false), 0.0);
  // A gap of 4 ms (gain 0.75) after the supervisor's zero: the supervisor's ceiling wins.
  EXPECT_EQ(ceiling.update(0.0085, 0.0, false), 0.0);
  EXPECT_TRUE(ceiling.gap_cut());
}

TEST(ResumeCeiling, TheWatchdogsRampIsWhereTheForceComesBackFrom) {
  ResumeCeiling ceiling(kPeriodS, ForceRampParams{});
  (void)ceilings_at({0.000, 0.001}, ceiling);
  ceiling.lower_to(0.5);
  EXPECT_NEAR(ceiling.update(0.002, 1.0, false), 0.625, 1e-12);
}

TEST(ResumeCeiling, ANonFiniteTimeRestartsFromZero) {
  ResumeCeiling ceiling(kPeriodS, ForceRampParams{});
  (void)ceilings_at({0.000, 0.001}, ceiling);
  EXPECT_EQ(ceiling.update(std::numeric_limits<double>::quiet_NaN(), 1.0, false), 0.0);
}

}  // namespace
}  // namespace hapsim
