// The step benchmark's cases: every method runs the same palpation (same steps, same contacts
// for the exact-refining methods), ratios are against the exact row, and the JSON has the rows.
#include "bench/step_cases.h"

#include <gtest/gtest.h>

namespace hapsim::bench {
namespace {

TEST(StepBench, MethodsRunTheSamePalpationBesideTheExactBaseline) {
  StepBenchOptions options;
  options.cases.push_back(
      {"knee", std::string(HAPSIM_SCENES_DIR) + "/knee_procedural.json", std::nullopt});
  options.methods = {"spheretree", "exact"};  // exact is moved first
  options.duration_s = 3.0;                   // the first press (the medial ligament)
  int progress_calls = 0;
  options.progress = [&](std::string_view, double) { ++progress_calls; };
  const std::vector<StepRow> rows = run_step_bench(options);
  ASSERT_EQ(rows.size(), 2u);
  EXPECT_EQ(rows[0].method, "exact");
  EXPECT_EQ(rows[1].method, "spheretree");
  EXPECT_GT(progress_calls, 1);
  for (const StepRow& r : rows) {
    EXPECT_EQ(r.steps, 3000u);
    EXPECT_EQ(r.tools, 1u);
    EXPECT_EQ(r.segments, 11u);
    EXPECT_EQ(r.pop_throughs, 0u);
    EXPECT_GT(r.contact_steps, 100u);
    EXPECT_GT(r.p50_us, 0.0);
    EXPECT_LE(r.p50_us, r.p99_us);
    EXPECT_LE(r.p99_us, r.max_us);
  }
  // The sphere tree refines exactly: the same contacts and forces as the exact query.
  EXPECT_EQ(rows[0].contact_steps, rows[1].contact_steps);
  EXPECT_NEAR(rows[0].peak_force_n, rows[1].peak_force_n, 1e-9);
  EXPECT_EQ(rows[0].p50_ratio_to_exact, 1.0);
  EXPECT_DOUBLE_EQ(rows[1].p50_ratio_to_exact, rows[1].p50_us / rows[0].p50_us);
  const auto j = step_rows_to_json(rows);
  ASSERT_EQ(j.size(), 2u);
  EXPECT_EQ(j[1]["method"], "spheretree");
  EXPECT_TRUE(j[0]["step_us"].contains("p99"));
  EXPECT_NE(format_step_table(rows).find("knee"), std::string::npos);
}

// The knee method's rows carry its error against the exact query (the sphere tree refines
// exactly: its error is rounding only); the exact row has none.
TEST(StepBench, ApproximateMethodsReportTheirErrorAgainstExact) {
  StepBenchOptions options;
  options.cases.push_back(
      {"knee", std::string(HAPSIM_SCENES_DIR) + "/knee_procedural.json", std::nullopt});
  options.methods = {"exact", "spheretree", "knee"};
  options.duration_s = 0.2;
  const std::vector<StepRow> rows = run_step_bench(options);
  ASSERT_EQ(rows.size(), 3u);
  EXPECT_LT(rows[0].error_p95_m, 0.0);  // exact: not measured
  EXPECT_GE(rows[1].error_max_m, 0.0);
  EXPECT_LT(rows[1].error_max_m, 1e-9);
  EXPECT_GT(rows[2].error_max_m, 0.0);
  EXPECT_GE(rows[2].error_max_m, rows[2].error_p95_m);
  EXPECT_GE(rows[2].error_miss_rate, 0.0);
  EXPECT_LE(rows[2].error_miss_rate, 1.0);
  const auto j = step_rows_to_json(rows);
  EXPECT_FALSE(j[0].contains("error_vs_exact"));
  EXPECT_DOUBLE_EQ(j[2]["error_vs_exact"]["max_m"].get<double>(), rows[2].error_max_m);
  EXPECT_NE(format_step_table(rows).find("error vs exact"), std::string::npos);
}

}  // namespace
}  // namespace hapsim::bench
