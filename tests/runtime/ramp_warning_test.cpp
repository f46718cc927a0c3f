// The words for a run whose force the safety ramps held down: none for a healthy run's occasional
// stall, one sentence with the share when a build or machine cannot keep the haptic rate (the
// Debug ASan viewer: 1 666 stalls in 12 s, the probe in the skin showing 0.00 N).
#include "hapsim/runtime/ramp_warning.h"

#include "hapsim/runtime/session.h"

#include <gtest/gtest.h>

#include <string>

namespace hapsim {
namespace {

TEST(RampWarning, TheShareIsRampedCyclesOverCycles) {
  EXPECT_DOUBLE_EQ(ramped_cycle_share(0, 0), 0.0);
  EXPECT_DOUBLE_EQ(ramped_cycle_share(1000, 250), 0.25);
  EXPECT_DOUBLE_EQ(ramped_cycle_share(1000, 5000), 1.0);  // never above all of them
}

TEST(RampWarning, AHealthyRunSaysNothing) {
  // 30 000 cycles, ten stalls of 8 ramped cycles each (the real-time figures' order).
  EXPECT_EQ(ramped_force_warning(30'000, 80), "");
  // A fifth exactly is not more than a fifth.
  EXPECT_EQ(ramped_force_warning(10'000, 2'000), "");
  // Too few cycles to say anything: the first second of a run's soft start.
  EXPECT_EQ(ramped_force_warning(999, 999), "");
}

TEST(RampWarning, ASlowBuildIsToldInWords) {
  // The ASan viewer's run: 12 s, about 11 000 of 12 000 cycles ramped.
  const std::string warning = ramped_force_warning(12'000, 11'000);
  EXPECT_NE(warning.find("92% of haptic cycles were held down by a safety ramp"), std::string::npos)
      << warning;
  EXPECT_NE(warning.find("contacts feel weaker and rougher than the model, or absent"),
            std::string::npos)
      << warning;
  EXPECT_NE(warning.find("cannot keep the haptic rate"), std::string::npos) << warning;
  EXPECT_NE(ramped_force_warning(10'000, 2'001), "");
}

TEST(RampWarning, TheRealTimeSummarySaysItOnItsOwnLine) {
  RealtimeSummary slow;
  slow.rate_hz = 640.0;
  slow.cycles = 12'000;
  slow.ramp_cycles = 11'000;
  const std::string text = format_realtime_summary(slow);
  EXPECT_NE(text.find("\nreal time: 92% of haptic cycles were held down by a safety ramp"),
            std::string::npos)
      << text;
  EXPECT_EQ(text.back(), '\n');

  RealtimeSummary healthy = slow;
  healthy.rate_hz = 999.0;
  healthy.ramp_cycles = 16;
  EXPECT_EQ(format_realtime_summary(healthy).find("held down"), std::string::npos);
}

}  // namespace
}  // namespace hapsim
