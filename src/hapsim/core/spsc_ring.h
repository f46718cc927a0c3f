// A bounded lock-free single-producer / single-consumer queue: the haptic thread hands every
// cycle's record to a slower consumer (the run's bookkeeping, the recorder's disk writer)
// without waiting. Unlike the triple buffer nothing is skipped; when the consumer falls behind
// by the whole capacity, push() refuses and the producer counts a drop instead of blocking.
#pragma once

#include <atomic>
#include <cstddef>
#include <vector>

namespace hapsim {

template <class T>
class SpscRing {
 public:
  /// Room for `capacity` items (rounded up to a power of two), all constructed now.
  explicit SpscRing(std::size_t capacity) : slots_(round_up(capacity)), mask_(slots_.size() - 1) {}

  /// haptic path (producer). Copies `item` in; false when full (the item is not queued).
  bool push(const T& item) noexcept {
    const std::size_t head = head_.load(std::memory_order_relaxed);
    if (head - tail_cache_ >= slots_.size()) {
      tail_cache_ = tail_.load(std::memory_order_acquire);
      if (head - tail_cache_ >= slots_.size()) {
        return false;
      }
    }
    slots_[head & mask_] = item;
    head_.store(head + 1, std::memory_order_release);
    return true;
  }

  /// Consumer: the oldest item, or nullptr when empty. Valid until pop().
  [[nodiscard]] const T* front() noexcept {
    const std::size_t tail = tail_.load(std::memory_order_relaxed);
    if (tail == head_.load(std::memory_order_acquire)) {
      return nullptr;
    }
    return &slots_[tail & mask_];
  }
  /// Consumer: drops the item front() returned.
  void pop() noexcept {
    tail_.store(tail_.load(std::memory_order_relaxed) + 1, std::memory_order_release);
  }

  [[nodiscard]] std::size_t capacity() const noexcept { return slots_.size(); }

 private:
  static std::size_t round_up(std::size_t n) {
    std::size_t p = 1;
    while (p < n) {
      p <<= 1U;
    }
    return p;
  }

  std::vector<T> slots_;
  std::size_t mask_;
  alignas(64) std::atomic<std::size_t> head_{0};  // written by the producer
  std::size_t tail_cache_ = 0;                    // producer's last look at tail_
  alignas(64) std::atomic<std::size_t> tail_{0};  // written by the consumer
};

}  // namespace hapsim
