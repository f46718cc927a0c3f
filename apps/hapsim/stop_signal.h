// SIGINT and SIGTERM as a request to stop, for the commands that run until stopped (serve,
// device, watch): they finish their run, print their summary and exit 0.
#pragma once

#include <atomic>
#include <csignal>

namespace hapsim::app {

inline std::atomic<bool>& stop_requested() {
  static std::atomic<bool> requested{false};
  return requested;
}

extern "C" inline void hapsim_request_stop(int /*signal*/) {
  stop_requested().store(true, std::memory_order_relaxed);
}

/// Installs the handlers; the flag they set.
inline const std::atomic<bool>& install_stop_signals() {
  static_assert(std::atomic<bool>::is_always_lock_free, "set from a signal handler");
  std::signal(SIGINT, hapsim_request_stop);
  std::signal(SIGTERM, hapsim_request_stop);
  return stop_requested();
}

}  // namespace hapsim::app
