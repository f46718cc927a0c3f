#include "hapsim/runtime/deadline_clock.h"

#include "hapsim/core/sanitizer_build.h"

#include <pthread.h>
#include <sched.h>
#include <sys/mman.h>
#include <sys/resource.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <ctime>

namespace hapsim {
namespace {

constexpr std::int64_t kNsPerS = 1'000'000'000;

timespec to_timespec(std::int64_t ns) {
  timespec t{};
  t.tv_sec = static_cast<time_t>(ns / kNsPerS);
  t.tv_nsec = static_cast<long>(ns % kNsPerS);
  return t;
}

}  // namespace

std::int64_t monotonic_ns() noexcept {
  timespec t{};
  clock_gettime(CLOCK_MONOTONIC, &t);
  return static_cast<std::int64_t>(t.tv_sec) * kNsPerS + static_cast<std::int64_t>(t.tv_nsec);
}

void sleep_until_ns(std::int64_t deadline_ns) noexcept {
  const timespec deadline = to_timespec(deadline_ns);
  while (clock_nanosleep(CLOCK_MONOTONIC, TIMER_ABSTIME, &deadline, nullptr) == EINTR) {
    // Interrupted by a signal: sleep again to the same absolute deadline.
  }
}

bool try_set_realtime_priority(int priority) noexcept {
  sched_param param{};
  param.sched_priority =
      std::clamp(priority, sched_get_priority_min(SCHED_FIFO), sched_get_priority_max(SCHED_FIFO));
  return pthread_setschedparam(pthread_self(), SCHED_FIFO, &param) == 0;
}

bool try_lock_process_memory() noexcept {
  // Sanitizers reserve terabytes of shadow memory: never lock those processes.
  if constexpr (kBuiltWithShadowSanitizer) {
    return false;
  }
  rlimit limit{};
  const bool unlimited = getrlimit(RLIMIT_MEMLOCK, &limit) == 0 && limit.rlim_cur == RLIM_INFINITY;
  if (geteuid() != 0 && !unlimited) {
    return false;
  }
  // MCL_ONFAULT: pages are locked as they are touched, so large reservations nobody touches
  // (allocator arenas, thread stacks) cost nothing; what the loop uses is touched before its
  // first cycle, and its stack by prefault_stack().
  return mlockall(MCL_CURRENT | MCL_FUTURE | MCL_ONFAULT) == 0;
}

void prefault_stack(std::size_t bytes) noexcept {
  constexpr std::size_t kMax = std::size_t{512} * 1024;
  volatile unsigned char stack[kMax];
  const std::size_t n = std::min(bytes, kMax);
  for (std::size_t i = 0; i < n; i += 4096) {
    stack[i] = 0;
  }
  // Read one back: the writes are not dead stores the compiler may drop.
  (void)stack[n > 0 ? n - 1 : 0];
}

long thread_page_faults() noexcept {
  rusage usage{};
  if (getrusage(RUSAGE_THREAD, &usage) != 0) {
    return -1;
  }
  return usage.ru_minflt + usage.ru_majflt;
}

DeadlineClock::DeadlineClock(std::int64_t period_ns, std::int64_t spin_ns) noexcept
    : period_ns_(std::max<std::int64_t>(1, period_ns)),
      // At most half a period: a real-time thread that never sleeps is throttled by the kernel
      // (sched_rt_runtime_us: 50 ms off every second here), far worse than any wake-up delay.
      spin_ns_(std::clamp<std::int64_t>(spin_ns, 0, period_ns_ / 2)) {}

void DeadlineClock::start() noexcept {
  deadline_ns_ = monotonic_ns();
}

std::int64_t DeadlineClock::wait_next() noexcept {
  deadline_ns_ += period_ns_;
  if (spin_ns_ > 0) {
    sleep_until_ns(deadline_ns_ - spin_ns_);
    std::int64_t now = monotonic_ns();
    while (now < deadline_ns_) {
      now = monotonic_ns();
    }
  } else {
    sleep_until_ns(deadline_ns_);
  }
  const std::int64_t now = monotonic_ns();
  if (now - deadline_ns_ > period_ns_) {
    deadline_ns_ = now;
  }
  return now;
}

}  // namespace hapsim
