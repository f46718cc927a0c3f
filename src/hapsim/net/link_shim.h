// A network link in a box (issue 12: "a link shim — seeded delay, jitter, i.i.d. and burst loss,
// reordering, outage — usable in process and on the receive side of the real DDS path, so tests
// and benchmarks need no root and no netem"). Samples go in with send(now) and come out of
// deliver(now) once due; what the link does to them is drawn from a seeded generator, so a run
// is reproducible. Fixed capacity, no allocation, no locks: one thread sends and delivers.
//
// Header-only and free of DDS: the in-process benchmark uses it with any sample type.
#pragma once

#include <algorithm>
#include <array>
#include <cstddef>
#include <cstdint>
#include <limits>
#include <random>

namespace hapsim::net {

struct LinkShimOptions {
  /// One-way delay, seconds (≥ 0).
  double delay_s = 0.0;
  /// Extra delay drawn per sample from U[0, jitter_s]. Samples overtake each other when it
  /// exceeds their spacing, unless `keep_order`.
  double jitter_s = 0.0;
  bool keep_order = false;
  /// Independent loss probability per sample.
  double loss = 0.0;
  /// Burst loss (Gilbert-Elliott, two states): per sample, the chance to enter a burst and to
  /// leave it; every sample sent during a burst is lost. 0: no bursts.
  double burst_enter = 0.0;
  double burst_exit = 1.0;
  /// The link is down in [outage_start_s, outage_start_s + outage_s): a sample on it at any
  /// time in that window is lost — sent during it, or sent before and still in flight at its
  /// start (a pulled cable loses what was on the wire too). Negative: none.
  double outage_start_s = -1.0;
  double outage_s = 0.0;
  std::uint64_t seed = 1;
};

/// Why the link dropped samples, counted.
struct LinkShimCounts {
  std::uint64_t sent = 0;
  std::uint64_t delivered = 0;
  std::uint64_t lost_random = 0;
  std::uint64_t lost_burst = 0;
  std::uint64_t lost_outage = 0;
  std::uint64_t lost_full = 0;  ///< more in flight than the capacity
  std::uint64_t reordered = 0;  ///< delivered after a sample sent later
};

template <typename T, std::size_t Capacity>
class LinkShim {
 public:
  explicit LinkShim(const LinkShimOptions& options) : options_(options), rng_(options.seed) {}

  /// Puts `sample` on the link at time `now_s`. False when the link lost it. haptic path
  bool send(const T& sample, double now_s) noexcept {
    ++counts_.sent;
    const std::uint64_t order = next_order_++;
    // Draw every random number for every sample, so changing one option leaves the others'
    // draws (and so the rest of the run) unchanged.
    const double u_loss = uniform_(rng_);
    const double u_burst = uniform_(rng_);
    const double u_jitter = uniform_(rng_);
    in_burst_ = in_burst_ ? !(u_burst < options_.burst_exit) : u_burst < options_.burst_enter;
    double due_s = now_s + options_.delay_s + options_.jitter_s * u_jitter;
    if (options_.keep_order && due_s < last_due_s_) {
      due_s = last_due_s_;
    }
    // On the link from now_s to due_s: lost if that meets the outage window.
    if (options_.outage_start_s >= 0.0 && options_.outage_s > 0.0 &&
        now_s < options_.outage_start_s + options_.outage_s &&
        due_s + kDueTolerance_s >= options_.outage_start_s) {
      ++counts_.lost_outage;
      return false;
    }
    if (in_burst_) {
      ++counts_.lost_burst;
      return false;
    }
    if (u_loss < options_.loss) {
      ++counts_.lost_random;
      return false;
    }
    if (in_flight_ == Capacity) {
      ++counts_.lost_full;
      return false;
    }
    last_due_s_ = std::max(last_due_s_, due_s);
    for (Slot& slot : slots_) {
      if (!slot.used) {
        slot = Slot{sample, due_s, order, true};
        ++in_flight_;
        break;
      }
    }
    return true;
  }

  /// Calls on_sample(const T&) for every sample due by `now_s`, earliest due first (sent order
  /// among equals). Returns how many. haptic path
  template <typename OnSample>
  std::size_t deliver(double now_s, OnSample&& on_sample) noexcept {
    // Due within a nanosecond counts as due: `now + delay` and a later `now` computed from a
    // cycle count differ by rounding only, and a sample must not wait a whole cycle for that.
    now_s += kDueTolerance_s;
    std::size_t count = 0;
    while (in_flight_ > 0) {
      Slot* next = nullptr;
      for (Slot& slot : slots_) {
        if (slot.used && slot.due_s <= now_s &&
            (next == nullptr || slot.due_s < next->due_s ||
             (slot.due_s == next->due_s && slot.order < next->order))) {
          next = &slot;
        }
      }
      if (next == nullptr) {
        break;
      }
      if (has_delivered_ && next->order < newest_delivered_order_) {
        ++counts_.reordered;
      }
      newest_delivered_order_ = std::max(newest_delivered_order_, next->order);
      has_delivered_ = true;
      next->used = false;
      --in_flight_;
      ++counts_.delivered;
      ++count;
      on_sample(next->sample);
    }
    return count;
  }

  [[nodiscard]] const LinkShimCounts& counts() const noexcept { return counts_; }
  [[nodiscard]] std::size_t in_flight() const noexcept { return in_flight_; }

 private:
  static constexpr double kDueTolerance_s = 1e-9;

  struct Slot {
    T sample{};
    double due_s = 0.0;
    std::uint64_t order = 0;
    bool used = false;
  };

  LinkShimOptions options_;
  std::mt19937_64 rng_;
  std::uniform_real_distribution<double> uniform_{0.0, 1.0};
  std::array<Slot, Capacity> slots_{};
  std::size_t in_flight_ = 0;
  std::uint64_t next_order_ = 0;
  std::uint64_t newest_delivered_order_ = 0;
  bool has_delivered_ = false;
  bool in_burst_ = false;
  double last_due_s_ = -std::numeric_limits<double>::infinity();
  LinkShimCounts counts_;
};

}  // namespace hapsim::net
