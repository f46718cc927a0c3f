// The soak's bookkeeping on a short run: the script repeats end to end, each minute gets its
// step-cost percentiles and RSS, and a world whose every repetition starts from the same state
// (the teleoperation rig, reset each time) replays its first repetition's forces exactly: the step
// is deterministic, so any difference would be state the reset forgot.
#include "bench/soak_cases.h"

#include <gtest/gtest.h>

namespace hapsim::bench {
namespace {

TEST(SoakBench, RepeatsTheScriptAndComparesEachRepetitionWithTheFirst) {
  SoakOptions options;
  options.scene = std::string(HAPSIM_SCENES_DIR) + "/teleop.json";
  options.duration_s = 70.0;  // more than a minute: two minute rows, several repetitions
  options.reset_between = true;
  const SoakResult r = run_soak(options);
  EXPECT_EQ(r.steps, 70000u);
  EXPECT_GT(r.script_s, 1.0);
  EXPECT_EQ(r.repetitions, static_cast<std::size_t>(70.0 / r.script_s) + 1);
  ASSERT_EQ(r.minutes.size(), 2u);
  for (const SoakMinute& m : r.minutes) {
    EXPECT_GT(m.p50_us, 0.0);
    EXPECT_LE(m.p50_us, m.p99_us);
    EXPECT_LE(m.p99_us, m.max_us);
    EXPECT_GT(m.peak_rss_bytes, 1u << 20);
    EXPECT_LE(m.rss_bytes, m.peak_rss_bytes);
  }
  EXPECT_GT(r.peak_force_n, 0.1);  // the grasp: there is a force to drift
  EXPECT_EQ(r.max_force_drift_n, 0.0);
  EXPECT_EQ(r.max_drift_from_second_n, 0.0);
  const auto j = soak_to_json(r);
  EXPECT_EQ(j["minutes"].size(), 2u);
  EXPECT_EQ(j["max_force_drift_n"], 0.0);
}

// The procedural knee, never reset: its script ends away from where it starts, so the first
// repetition (from a fresh world) and the second (from where the script left it, one step's jump
// away) differ; from then on every repetition is the second one again, bit for bit.
TEST(SoakBench, AKneeNeverResetRepeatsItsSecondPalpationExactly) {
  SoakOptions options;
  options.scene = std::string(HAPSIM_SCENES_DIR) + "/knee_procedural.json";
  options.duration_s = 35.0;  // three repetitions of the 10.5 s palpation and a part
  const SoakResult r = run_soak(options);
  ASSERT_EQ(r.repetitions, 4u);
  EXPECT_GT(r.peak_force_n, 1.0);
  EXPECT_EQ(r.max_drift_from_second_n, 0.0);
}

TEST(SoakBench, ProcessMemoryIsRead) {
  const ProcessMemory m = process_memory();
  EXPECT_GT(m.rss_bytes, 0u);
  EXPECT_GE(m.peak_rss_bytes, m.rss_bytes);
}

}  // namespace
}  // namespace hapsim::bench
