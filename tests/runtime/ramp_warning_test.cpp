// The words for a run whose force lateness held down: none for a healthy run's occasional stall,
// one sentence with the share when a build or machine cannot keep the haptic rate (the Debug ASan
// viewer: 1 666 stalls in 12 s, the probe in the skin showing 0.00 N).
#include "hapsim/runtime/ramp_warning.h"

#include "hapsim/runtime/session.h"
#include "hapsim/runtime/session_json.h"

#include <gtest/gtest.h>

#include <string>

namespace hapsim {
namespace {

TEST(RampWarning, TheShareIsLateRampCyclesOverCycles) {
  EXPECT_DOUBLE_EQ(late_ramp_share(0, 0), 0.0);
  EXPECT_DOUBLE_EQ(late_ramp_share(1000, 250), 0.25);
  EXPECT_DOUBLE_EQ(late_ramp_share(1000, 5000), 1.0);  // never above all of them
}

TEST(RampWarning, AHealthyRunSaysNothing) {
  // 30 000 cycles, ten stalls of 8 capped cycles each (the real-time figures' order).
  EXPECT_EQ(late_ramp_warning(30'000, 80), "");
  // A fifth is not more than a fifth, nor is what prints as 20%.
  EXPECT_EQ(late_ramp_warning(10'000, 2'000), "");
  EXPECT_EQ(late_ramp_warning(10'000, 2'049), "");
  // Too few cycles to say anything, however many were capped.
  EXPECT_EQ(late_ramp_warning(999, 999), "");
}

TEST(RampWarning, ASlowBuildIsToldInWords) {
  // The ASan viewer's run: 12 s, about 11 000 of 12 000 cycles capped.
  const std::string warning = late_ramp_warning(12'000, 11'000);
  EXPECT_NE(warning.find("92% of haptic cycles were capped because cycles came late"),
            std::string::npos)
      << warning;
  EXPECT_NE(warning.find("contacts feel weaker and rougher than the model, or absent"),
            std::string::npos)
      << warning;
  EXPECT_NE(warning.find("cannot keep the haptic rate"), std::string::npos) << warning;
  EXPECT_NE(late_ramp_warning(10'000, 2'050).find("21% of haptic cycles"), std::string::npos);
}

TEST(RampWarning, TheRealTimeSummaryAndItsJsonSayIt) {
  RealtimeSummary slow;
  slow.rate_hz = 640.0;
  slow.cycles = 12'000;
  slow.ramp_cycles = 11'500;  // the device was also unhealthy for a while: not counted
  slow.late_ramp_cycles = 11'000;
  const std::string text = format_realtime_summary(slow);
  EXPECT_NE(text.find("\nreal time: 92% of haptic cycles were capped because cycles came late"),
            std::string::npos)
      << text;
  EXPECT_EQ(text.back(), '\n');
  const nlohmann::json j = realtime_json(slow);
  EXPECT_EQ(j["cycles"].get<int>(), 12'000);
  EXPECT_EQ(j["late_ramp_cycles"].get<int>(), 11'000);
  EXPECT_NEAR(j["late_ramp_share"].get<double>(), 11.0 / 12.0, 1e-12);
  ASSERT_TRUE(j.contains("warning")) << j.dump(2);
  EXPECT_EQ(j["warning"].get<std::string>(), late_ramp_warning(12'000, 11'000));

  // Capped for an unhealthy device, not for lateness: no sentence about the rate.
  RealtimeSummary lost_device = slow;
  lost_device.late_ramp_cycles = 40;
  EXPECT_EQ(format_realtime_summary(lost_device).find("came late"), std::string::npos);
  EXPECT_FALSE(realtime_json(lost_device).contains("warning"));
}

}  // namespace
}  // namespace hapsim
