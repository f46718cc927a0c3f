// The consumer side of a haptic loop's record ring: hands every record to `consume` on the
// calling thread until the loop has stopped and the ring is empty. Used by the real-time runs'
// bookkeeping (knee and teleop) — never on the haptic thread.
#pragma once

#include "hapsim/core/spsc_ring.h"
#include "hapsim/runtime/haptic_loop.h"

#include <atomic>
#include <chrono>
#include <thread>

namespace hapsim {

/// `stop` (may be null), once set, asks the loop to stop at the next poll: checked every poll,
/// not per record, since a paused world steps no cycle and so makes no record (a paused serve
/// once ignored SIGINT).
template <class Record, class Consume>
void drain_until_stopped(HapticLoop& loop, SpscRing<Record>& ring, Consume&& consume,
                         const std::atomic<bool>* stop = nullptr,
                         std::chrono::milliseconds poll = std::chrono::milliseconds(5)) {
  for (;;) {
    if (stop != nullptr && stop->load(std::memory_order_relaxed)) {
      loop.request_stop();
    }
    // Read before draining: a record pushed before the loop stopped is drained below.
    const bool running = loop.running();
    while (const Record* r = ring.front()) {
      consume(*r);
      ring.pop();
    }
    if (!running) {
      return;
    }
    std::this_thread::sleep_for(poll);
  }
}

}  // namespace hapsim
