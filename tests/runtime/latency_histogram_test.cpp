// The loop's timing histogram against exact nearest-rank percentiles of the same samples: equal
// to within one bin width, never below the true value, never above the largest sample.
#include "hapsim/runtime/latency_histogram.h"

#include "hapsim/runtime/session.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <random>
#include <vector>

namespace hapsim {
namespace {

TEST(LatencyHistogram, PercentilesMatchExactNearestRankWithinABin) {
  LatencyHistogram h;
  std::mt19937 rng(42);
  std::lognormal_distribution<double> dist(std::log(5.0), 1.0);  // a step-cost-like spread
  std::vector<double> samples;
  for (int i = 0; i < 20'000; ++i) {
    const double v = dist(rng);
    samples.push_back(v);
    h.record_us(v);
  }
  std::vector<double> sorted = samples;
  const SampleSummary exact = summarize_samples(sorted);
  const LatencyPercentilesUs s = h.summary();
  EXPECT_EQ(s.count, 20'000u);
  const auto bin_width = [](double v) { return v < 1000.0 ? 0.1 : 10.0; };
  EXPECT_GE(s.p50, exact.p50);
  EXPECT_LE(s.p50, exact.p50 + bin_width(exact.p50));
  EXPECT_GE(s.p99, exact.p99);
  EXPECT_LE(s.p99, exact.p99 + bin_width(exact.p99));
  EXPECT_DOUBLE_EQ(s.max, exact.max);
  EXPECT_NEAR(s.mean, exact.mean, 1e-9 * exact.mean);
}

TEST(LatencyHistogram, CoarseRangeOverflowAndCounts) {
  LatencyHistogram h;
  EXPECT_EQ(h.percentile_us(0.5), 0.0);
  h.record_us(1.0);
  h.record_us(2500.0);   // 2.5 ms: a missed deadline's period
  h.record_us(250'000);  // beyond the last bin
  h.record_us(-3.0);     // counts as 0
  h.record_us(std::numeric_limits<double>::quiet_NaN());
  EXPECT_EQ(h.count(), 5u);
  EXPECT_EQ(h.count_above_us(2000.0), 3u);  // 2500, 250000 and the NaN (overflow)
  EXPECT_EQ(h.summary().max, std::numeric_limits<double>::infinity());  // the NaN sample
  EXPECT_EQ(h.percentile_us(1.0), std::numeric_limits<double>::infinity());
  EXPECT_EQ(LatencyHistogram::bin_of(999.95), LatencyHistogram::kFineBins - 1);
  EXPECT_EQ(LatencyHistogram::bin_of(1000.0), LatencyHistogram::kFineBins);
  EXPECT_DOUBLE_EQ(LatencyHistogram::upper_edge_us(LatencyHistogram::bin_of(2500.0)), 2510.0);
  h.reset();
  EXPECT_EQ(h.count(), 0u);
  EXPECT_EQ(h.summary().max, 0.0);
}

}  // namespace
}  // namespace hapsim
