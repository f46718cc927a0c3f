// `hapsim bench network --quick --json F` end to end: the real binary writes one JSON row per
// run with the issue's fields, the wall rows hold the hand and wall springs in series, raw force
// is caught unstable once there is delay and the local model is not; bad arguments exit 2.
#ifdef HAPSIM_HAVE_BENCH_CASES

#include "hapsim_process.h"

#include <nlohmann/json.hpp>

#include <cmath>
#include <fstream>
#include <string>

#include <gtest/gtest.h>

namespace hapsim::test {
namespace {

TEST(NetworkBench, QuickRunWritesRowsWithTheIssuesFields) {
  const auto json_path = temp_path("network.json");
  const RunResult r = run_hapsim("bench network --quick --json " + json_path.string());
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_NE(r.output.find("steady_N"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("wrote " + json_path.string()), std::string::npos);
  std::ifstream in(json_path);
  const nlohmann::json rows = nlohmann::json::parse(in);
  ASSERT_TRUE(rows.is_array());
  // 2 modes × 2 environments × 2 hands × 3 delays × 2 losses, then an outage row per
  // mode × environment × hand.
  ASSERT_EQ(rows.size(), 48u + 8u);
  int outages = 0;
  for (const nlohmann::json& row : rows) {
    SCOPED_TRACE(row.dump());
    for (const char* field : {"mode", "delay_ms", "loss", "hand", "energy_generated_j",
                              "steady_force_error", "hold_ripple_rms_n", "peak_force_n", "stable",
                              "environment", "outage_ms", "outage_force_zero_s"}) {
      ASSERT_TRUE(row.contains(field)) << field;
    }
    const std::string mode = row["mode"];
    const std::string environment = row["environment"];
    const std::string hand = row["hand"];
    ASSERT_TRUE(mode == "raw" || mode == "local-model");
    ASSERT_TRUE(environment == "tissue" || environment == "wall");
    ASSERT_TRUE(hand == "relaxed" || hand == "stiff");
    EXPECT_TRUE(row["stable"].is_boolean());
    EXPECT_GE(row["energy_generated_j"].get<double>(), 0.0);
    EXPECT_DOUBLE_EQ(row["jitter_max_ms"].get<double>(), 0.5 * row["delay_ms"].get<double>());
    const bool outage = row["outage_ms"].get<double>() > 0.0;
    outages += outage ? 1 : 0;
    if (mode == "local-model") {
      EXPECT_TRUE(row["stable"].get<bool>());
      EXPECT_LT(row["hold_ripple_rms_n"].get<double>(), 0.05);
      EXPECT_LT(std::abs(row["steady_force_error"].get<double>()), 0.05);
      if (outage) {
        ASSERT_TRUE(row["outage_force_zero_after_last_model_s"].is_number());
        EXPECT_LE(row["outage_force_zero_after_last_model_s"].get<double>(), 0.150 + 1e-9);
      }
    } else if (row["delay_ms"].get<double>() >= 20.0) {
      EXPECT_FALSE(row["stable"].get<bool>());
    } else if (row["delay_ms"].get<double>() == 0.0 && !outage) {
      EXPECT_TRUE(row["stable"].get<bool>());
    }
    if (environment == "wall" && row["stable"].get<bool>()) {
      // The hand spring (300 or 1200 N/m, target 20 mm in) in series with the 1000 N/m wall.
      const double k_h = hand == "relaxed" ? 300.0 : 1200.0;
      const double hold_n = k_h * 1000.0 / (k_h + 1000.0) * 0.020;
      EXPECT_NEAR(row["steady_force_n"].get<double>(), hold_n, 1e-3 * hold_n);
    }
    if (!outage) {
      EXPECT_TRUE(row["outage_force_zero_s"].is_null());
    }
  }
  EXPECT_EQ(outages, 8);
}

TEST(NetworkBench, BadArgumentsExitTwo) {
  EXPECT_EQ(run_hapsim("bench network --modes magic").exit_code, 2);
  EXPECT_EQ(run_hapsim("bench network --losses 150").exit_code, 2);
  const RunResult r = run_hapsim("bench network --quick --json /nonexistent/dir/network.json");
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_NE(r.output.find("/nonexistent/dir/network.json"), std::string::npos) << r.output;
}

}  // namespace
}  // namespace hapsim::test

#endif  // HAPSIM_HAVE_BENCH_CASES
