// SIGINT and SIGTERM as a request to stop, for the commands that run until stopped or for long
// (view, serve, device, watch, bench): they stop their loop, ramp the force to zero, write their
// summary and JSON, and exit 128 + the signal (130 for SIGINT, 143 for SIGTERM), as a shell
// expects of a program a signal ended (docs/cli.md).
#pragma once

#include <atomic>
#include <csignal>

namespace hapsim::app {

/// The signal that asked to stop, 0 while none did.
inline std::atomic<int>& stop_signal_number() {
  static std::atomic<int> number{0};
  return number;
}

inline std::atomic<bool>& stop_requested() {
  static std::atomic<bool> requested{false};
  return requested;
}

extern "C" inline void hapsim_request_stop(int signal) {
  stop_signal_number().store(signal, std::memory_order_relaxed);
  stop_requested().store(true, std::memory_order_relaxed);
}

/// Installs the handlers; the flag they set.
inline const std::atomic<bool>& install_stop_signals() {
  static_assert(std::atomic<bool>::is_always_lock_free, "set from a signal handler");
  static_assert(std::atomic<int>::is_always_lock_free, "set from a signal handler");
  std::signal(SIGINT, hapsim_request_stop);
  std::signal(SIGTERM, hapsim_request_stop);
  return stop_requested();
}

/// The exit status for a run a signal stopped (128 + the signal), 0 when none did.
inline int stopped_by_signal_status() {
  const int signal = stop_signal_number().load(std::memory_order_relaxed);
  return signal == 0 ? 0 : 128 + signal;
}

/// "SIGINT" or "SIGTERM" for the signal that stopped the run (for its JSON); "" when none did.
inline const char* stop_signal_name() {
  switch (stop_signal_number().load(std::memory_order_relaxed)) {
    case SIGINT:
      return "SIGINT";
    case SIGTERM:
      return "SIGTERM";
    case 0:
      return "";
    default:
      return "signal";
  }
}

/// A command's exit status: `status` (a failure) unless it is 0 and a signal stopped the run.
inline int with_signal_status(int status) {
  return status != 0 ? status : stopped_by_signal_status();
}

}  // namespace hapsim::app
