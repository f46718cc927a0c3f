#include "hapsim/core/statistics.h"

#include <algorithm>
#include <cmath>

namespace hapsim {

double nearest_rank_percentile(std::span<double> samples, double q) {
  const std::size_t n = samples.size();
  if (n == 0) {
    return 0.0;
  }
  const double rank = std::ceil(std::clamp(q, 0.0, 1.0) * static_cast<double>(n));
  const std::size_t k = std::clamp<std::size_t>(static_cast<std::size_t>(rank), 1, n) - 1;
  std::nth_element(samples.begin(), samples.begin() + static_cast<std::ptrdiff_t>(k),
                   samples.end());
  return samples[k];
}

SampleSummary summarize_samples(std::span<double> samples) {
  SampleSummary s;
  s.count = samples.size();
  if (samples.empty()) {
    return s;
  }
  double sum = 0.0;
  double largest = samples[0];
  for (const double v : samples) {
    sum += v;
    largest = std::max(largest, v);
  }
  s.mean = sum / static_cast<double>(samples.size());
  s.max = largest;
  s.p50 = nearest_rank_percentile(samples, 0.50);
  s.p99 = nearest_rank_percentile(samples, 0.99);
  return s;
}

}  // namespace hapsim
