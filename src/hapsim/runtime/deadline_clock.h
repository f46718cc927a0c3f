// The haptic loop's clock (architecture.md#real-time): absolute deadlines every period on
// CLOCK_MONOTONIC, so a late cycle does not shift every later one (clock_nanosleep with
// TIMER_ABSTIME), and real-time scheduling when the system allows it.
//
// Measured on these VMs (STACK.md): a plain absolute sleep wakes 0.1-1 ms late at p99; with
// SCHED_FIFO, sleeping to ~200 µs before the deadline and spinning the rest keeps p99 under
// 50 µs. So the clock spins only when it runs with real-time priority (a spinning normal thread
// would just be preempted mid-spin).
#pragma once

#include <cstddef>
#include <cstdint>

namespace hapsim {

/// CLOCK_MONOTONIC now, nanoseconds.
[[nodiscard]] std::int64_t monotonic_ns() noexcept;

/// Sleeps the calling thread until CLOCK_MONOTONIC reaches `deadline_ns` (EINTR-safe).
void sleep_until_ns(std::int64_t deadline_ns) noexcept;

/// Asks for SCHED_FIFO at `priority` (1..99) for the calling thread. Returns false, quietly,
/// when not permitted (EPERM for non-root, containers without CAP_SYS_NICE) or unsupported.
[[nodiscard]] bool try_set_realtime_priority(int priority) noexcept;

/// Locks the process's pages in RAM as they are touched, present and future (mlockall with
/// MCL_ONFAULT), so no cycle waits for a page to be read back from swap; only where it cannot make
/// a later allocation fail (as root or with an unlimited RLIMIT_MEMLOCK: a small limit would turn a
/// big allocation into bad_alloc) and never under a sanitizer. Returns true if locked. Call before
/// the real-time threads start.
[[nodiscard]] bool try_lock_process_memory() noexcept;

/// Touches `bytes` of the calling thread's stack below this frame, so the cycle's deeper calls
/// find it mapped (with mlockall's MCL_FUTURE, it stays so).
void prefault_stack(std::size_t bytes) noexcept;

/// Page faults (minor + major) the calling thread has taken so far (getrusage RUSAGE_THREAD);
/// -1 when unavailable. No allocation.
[[nodiscard]] long thread_page_faults() noexcept;

class DeadlineClock {
 public:
  /// `spin_ns`: wake this long before each deadline and spin to it (0: sleep only).
  DeadlineClock(std::int64_t period_ns, std::int64_t spin_ns) noexcept;

  /// Starts the schedule: the first deadline is one period after now.
  void start() noexcept;
  /// haptic path. Waits for the next deadline and returns the wake-up time (ns). When the loop is
  /// more than a whole period late, the schedule restarts from now instead of firing a burst of
  /// catch-up cycles (a haptic device wants the newest force, not old ones fast).
  std::int64_t wait_next() noexcept;

 private:
  std::int64_t period_ns_;
  std::int64_t spin_ns_;
  std::int64_t deadline_ns_ = 0;
};

}  // namespace hapsim
