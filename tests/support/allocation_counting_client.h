// A HapticClient that wraps another and counts the heap allocations made by the thread that runs
// it (the haptic thread) from its warm-up step to its last step: everything the loop and the
// client do in those cycles (read, step, safety, write, publish) is inside the window.
#pragma once

#include "hapsim/runtime/haptic_loop.h"
#include "support/allocation_counter.h"

namespace hapsim::test {

class AllocationCountingClient final : public HapticClient {
 public:
  explicit AllocationCountingClient(HapticClient& inner, int warmup_steps = 5)
      : inner_(inner), warmup_steps_(warmup_steps) {}

  const DeviceCommand& step(const DeviceInput& input, double dt_s) override {
    if (steps_++ == warmup_steps_) {
      first_ = thread_allocation_count();
    }
    last_ = thread_allocation_count();
    return inner_.step(input, dt_s);
  }
  void after_cycle(const HapticCycle& cycle) noexcept override { inner_.after_cycle(cycle); }
  bool take_soft_start() noexcept override { return inner_.take_soft_start(); }

  /// Allocations on the haptic thread between the warm-up step and the last step (read after the
  /// loop stopped).
  [[nodiscard]] long allocations() const { return last_ - first_; }
  [[nodiscard]] int steps() const { return steps_; }

 private:
  HapticClient& inner_;
  int warmup_steps_;
  int steps_ = 0;
  long first_ = 0;
  long last_ = 0;
};

}  // namespace hapsim::test
