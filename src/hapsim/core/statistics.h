// Percentiles of measured samples, defined once for every report (step costs, frame times, query
// times): the nearest-rank percentile, a value that was actually measured, never interpolated.
#pragma once

#include <cstddef>
#include <span>

namespace hapsim {

/// Nearest-rank percentile `q` ∈ [0, 1] of `samples`: the ⌈q·n⌉-th smallest (at least the
/// smallest). Reorders `samples` (nth_element, O(n)); 0 for no samples.
[[nodiscard]] double nearest_rank_percentile(std::span<double> samples, double q);

/// p50, p99, max and mean of a set of samples, in the samples' unit.
struct SampleSummary {
  double p50 = 0.0;
  double p99 = 0.0;
  double max = 0.0;
  double mean = 0.0;
  std::size_t count = 0;
};

/// Reorders `samples`; all zero for no samples.
[[nodiscard]] SampleSummary summarize_samples(std::span<double> samples);

}  // namespace hapsim
