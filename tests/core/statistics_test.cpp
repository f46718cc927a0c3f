// Nearest-rank percentiles (the one definition every report uses), against hand-counted ranks.
#include "hapsim/core/statistics.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <numeric>
#include <vector>

namespace hapsim {
namespace {

TEST(Statistics, NearestRankPercentilesOfOneToHundred) {
  std::vector<double> samples(100);
  std::iota(samples.begin(), samples.end(), 1.0);
  std::reverse(samples.begin(), samples.end());
  const SampleSummary s = summarize_samples(samples);
  EXPECT_EQ(s.p50, 50.0);
  EXPECT_EQ(s.p99, 99.0);
  EXPECT_EQ(s.max, 100.0);
  EXPECT_DOUBLE_EQ(s.mean, 50.5);
  EXPECT_EQ(s.count, 100U);
}

TEST(Statistics, SmallAndEmptySets) {
  std::vector<double> one{7.0};
  EXPECT_EQ(summarize_samples(one).p99, 7.0);
  EXPECT_EQ(nearest_rank_percentile(one, 0.0), 7.0);
  std::vector<double> none;
  EXPECT_EQ(summarize_samples(none).max, 0.0);
  EXPECT_EQ(nearest_rank_percentile(none, 0.5), 0.0);
  // Ten samples: p99 is the 10th smallest (⌈9.9⌉), p50 the 5th, p10 the 1st.
  std::vector<double> ten{9, 3, 7, 1, 5, 10, 2, 8, 4, 6};
  EXPECT_EQ(nearest_rank_percentile(ten, 0.99), 10.0);
  EXPECT_EQ(nearest_rank_percentile(ten, 0.5), 5.0);
  EXPECT_EQ(nearest_rank_percentile(ten, 0.1), 1.0);
}

}  // namespace
}  // namespace hapsim
