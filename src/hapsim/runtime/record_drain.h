// The consumer side of a haptic loop's record ring: hands every record to `consume` on the
// calling thread until the loop has stopped and the ring is empty. Used by the real-time runs'
// bookkeeping (knee and teleop) — never on the haptic thread.
#pragma once

#include "hapsim/core/spsc_ring.h"
#include "hapsim/runtime/haptic_loop.h"

#include <chrono>
#include <thread>

namespace hapsim {

template <class Record, class Consume>
void drain_until_stopped(const HapticLoop& loop, SpscRing<Record>& ring, Consume&& consume,
                         std::chrono::milliseconds poll = std::chrono::milliseconds(5)) {
  for (;;) {
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
