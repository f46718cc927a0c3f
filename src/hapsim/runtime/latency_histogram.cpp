#include "hapsim/runtime/latency_histogram.h"

#include <algorithm>
#include <cmath>
#include <limits>

namespace hapsim {

int LatencyHistogram::bin_of(double value_us) noexcept {
  if (!(value_us > 0.0)) {
    return std::isnan(value_us) ? kBinCount - 1 : 0;
  }
  if (value_us < 1000.0) {
    return std::min(kFineBins - 1, static_cast<int>(value_us * 10.0));
  }
  if (value_us < 100'000.0) {
    return kFineBins + std::min(kCoarseBins - 1, static_cast<int>((value_us - 1000.0) / 10.0));
  }
  return kBinCount - 1;
}

double LatencyHistogram::upper_edge_us(int bin) noexcept {
  if (bin < kFineBins) {
    return 0.1 * static_cast<double>(bin + 1);
  }
  if (bin < kFineBins + kCoarseBins) {
    return 1000.0 + 10.0 * static_cast<double>(bin - kFineBins + 1);
  }
  return std::numeric_limits<double>::infinity();
}

void LatencyHistogram::record_us(double value_us) noexcept {
  std::atomic<std::uint32_t>& bin = bins_[static_cast<std::size_t>(bin_of(value_us))];
  // One writer: load + store is enough (no read-modify-write needed), and stays lock-free.
  bin.store(bin.load(std::memory_order_relaxed) + 1, std::memory_order_relaxed);
  const double v = std::isfinite(value_us) ? std::max(0.0, value_us) : 0.0;
  sum_us_.store(sum_us_.load(std::memory_order_relaxed) + v, std::memory_order_relaxed);
  // A non-finite sample lands in the overflow bin: the maximum says so (infinite).
  const double as_max = std::isfinite(value_us) ? v
                        : std::isnan(value_us) || value_us > 0.0
                            ? std::numeric_limits<double>::infinity()
                            : 0.0;
  if (as_max > max_us_.load(std::memory_order_relaxed)) {
    max_us_.store(as_max, std::memory_order_relaxed);
  }
  count_.store(count_.load(std::memory_order_relaxed) + 1, std::memory_order_release);
}

double LatencyHistogram::percentile_us(double q) const noexcept {
  const std::uint64_t n = count_.load(std::memory_order_acquire);
  if (n == 0) {
    return 0.0;
  }
  const double rank_d = std::ceil(std::clamp(q, 0.0, 1.0) * static_cast<double>(n));
  const std::uint64_t rank = std::max<std::uint64_t>(1, static_cast<std::uint64_t>(rank_d));
  std::uint64_t seen = 0;
  for (int b = 0; b < kBinCount; ++b) {
    seen += bins_[static_cast<std::size_t>(b)].load(std::memory_order_relaxed);
    if (seen >= rank) {
      // Never report more than the largest sample actually seen.
      return std::min(upper_edge_us(b), max_us_.load(std::memory_order_relaxed));
    }
  }
  return max_us_.load(std::memory_order_relaxed);  // a reader racing the writer
}

LatencyPercentilesUs LatencyHistogram::summary() const noexcept {
  LatencyPercentilesUs s;
  s.count = count_.load(std::memory_order_acquire);
  if (s.count == 0) {
    return s;
  }
  s.p50 = percentile_us(0.50);
  s.p99 = percentile_us(0.99);
  s.max = max_us_.load(std::memory_order_relaxed);
  s.mean = sum_us_.load(std::memory_order_relaxed) / static_cast<double>(s.count);
  return s;
}

std::uint64_t LatencyHistogram::count_above_us(double threshold_us) const noexcept {
  std::uint64_t n = 0;
  for (int b = bin_of(threshold_us) + 1; b < kBinCount; ++b) {
    n += bins_[static_cast<std::size_t>(b)].load(std::memory_order_relaxed);
  }
  return n;
}

void LatencyHistogram::reset() noexcept {
  for (auto& b : bins_) {
    b.store(0, std::memory_order_relaxed);
  }
  sum_us_.store(0.0, std::memory_order_relaxed);
  max_us_.store(0.0, std::memory_order_relaxed);
  count_.store(0, std::memory_order_release);
}

}  // namespace hapsim
