// A lock-free single-producer / single-consumer triple buffer (architecture.md#real-time): the haptic thread
// publishes a snapshot every cycle without ever waiting, and a slower reader (the viewer, the
// network) always gets the newest complete one, never a torn mix of two cycles.
//
// Three slots: the writer owns one ("back"), the reader owns one ("front"), the third is the
// hand-over slot ("middle"). publish() swaps back and middle and marks middle fresh; update()
// swaps front and middle when middle is fresh. Each is one atomic exchange, so neither side
// can block the other, and a slot is only ever touched by the side that owns it.
#pragma once

#include <array>
#include <atomic>
#include <cstdint>
#include <new>

namespace hapsim {

template <class T>
class TripleBuffer {
 public:
  /// All three slots start as copies of `initial` (size containers here: publishing must not
  /// allocate).
  explicit TripleBuffer(const T& initial) : slots_{Slot{initial}, Slot{initial}, Slot{initial}} {}
  TripleBuffer(const TripleBuffer&) = delete;
  TripleBuffer& operator=(const TripleBuffer&) = delete;
  TripleBuffer(TripleBuffer&&) = delete;
  TripleBuffer& operator=(TripleBuffer&&) = delete;
  ~TripleBuffer() = default;

  // --- writer side (one thread) ---

  /// haptic path. The slot to fill. It holds what was published two or more publishes ago (or
  /// the initial value), so a writer either rewrites it whole or tracks per-slot changes with
  /// write_index().
  [[nodiscard]] T& write_slot() noexcept { return slots_[back_].value; }
  /// Which of the three slots write_slot() is (0..2), for writers that update slots by delta.
  [[nodiscard]] int write_index() const noexcept { return back_; }
  /// haptic path. Hands the filled slot to the reader side; never waits.
  void publish() noexcept {
    back_ = middle_.exchange(back_ | kFresh, std::memory_order_acq_rel) & kIndexMask;
  }

  // --- reader side (one thread) ---

  /// Takes the newest published slot if there is one the reader has not seen; returns whether
  /// read_slot() changed.
  bool update() noexcept {
    if ((middle_.load(std::memory_order_relaxed) & kFresh) == 0) {
      return false;
    }
    front_ = middle_.exchange(front_, std::memory_order_acq_rel) & kIndexMask;
    return true;
  }
  /// The reader's current slot: stable until the reader's next update().
  [[nodiscard]] const T& read_slot() const noexcept { return slots_[front_].value; }

 private:
  static constexpr int kIndexMask = 0x3;
  static constexpr int kFresh = 0x4;
  // Each slot on its own cache lines, so the two threads do not false-share.
  struct alignas(64) Slot {
    T value;
  };

  std::array<Slot, 3> slots_;
  alignas(64) std::atomic<int> middle_{1};
  alignas(64) int back_ = 0;   // writer only
  alignas(64) int front_ = 2;  // reader only
};

}  // namespace hapsim
