// Durations of the haptic loop (cycle cost, period, period jitter) kept as a fixed-size histogram:
// recording is one relaxed increment (haptic path: no allocation, no lock, however long the run),
// and another thread can read percentiles live while the loop runs (the viewer's data area).
//
// Bins: 0.1 µs wide up to 1 ms, then 10 µs wide up to 100 ms, then one overflow bin. Percentiles
// are the upper edge of the bin holding the nearest-rank sample, so they never understate; the
// exact maximum is kept beside.
#pragma once

#include <array>
#include <atomic>
#include <cstdint>

namespace hapsim {

struct LatencyPercentilesUs {
  double p50 = 0.0;
  double p99 = 0.0;
  double max = 0.0;
  double mean = 0.0;
  std::uint64_t count = 0;
};

class LatencyHistogram {
 public:
  LatencyHistogram() = default;
  LatencyHistogram(const LatencyHistogram&) = delete;
  LatencyHistogram& operator=(const LatencyHistogram&) = delete;
  LatencyHistogram(LatencyHistogram&&) = delete;
  LatencyHistogram& operator=(LatencyHistogram&&) = delete;
  ~LatencyHistogram() = default;

  /// haptic path; one writer thread. A negative or non-finite value counts as 0 / overflow.
  void record_us(double value_us) noexcept;

  /// Any thread. Nearest-rank percentile q in (0, 1], microseconds (0 when empty).
  [[nodiscard]] double percentile_us(double q) const noexcept;
  [[nodiscard]] LatencyPercentilesUs summary() const noexcept;
  [[nodiscard]] std::uint64_t count() const noexcept {
    return count_.load(std::memory_order_relaxed);
  }
  /// Samples above `threshold_us` (resolution: the bin width there).
  [[nodiscard]] std::uint64_t count_above_us(double threshold_us) const noexcept;

  /// Writer thread only (or when no thread writes).
  void reset() noexcept;

  static constexpr int kFineBins = 10'000;   // 0.1 µs up to 1 ms
  static constexpr int kCoarseBins = 9'900;  // 10 µs from 1 ms up to 100 ms
  static constexpr int kBinCount = kFineBins + kCoarseBins + 1;

  /// Bin of a value and the upper edge of a bin, microseconds (public for tests).
  [[nodiscard]] static int bin_of(double value_us) noexcept;
  [[nodiscard]] static double upper_edge_us(int bin) noexcept;

 private:
  std::array<std::atomic<std::uint32_t>, kBinCount> bins_{};
  std::atomic<std::uint64_t> count_{0};
  std::atomic<double> sum_us_{0.0};
  std::atomic<double> max_us_{0.0};
};

}  // namespace hapsim
