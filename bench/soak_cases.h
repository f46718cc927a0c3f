// The soak (issue 14 item 5, `hapsim bench soak`): an hour of simulated time of one scene's
// scripted run, fast-forward (each step called directly, as fast as it goes), the script repeated
// end to end. Per minute of simulated time: the step cost's percentiles (each step timed alone)
// and the process's peak RSS; per repetition: how far its forces are from the first
// repetition's at the same time in the script.
//
// The knee is never reset between repetitions (its tissue must recover by itself: what a long
// session does); a teleoperation rig is reset to its start before each (a pick-and-place moves
// the ball), so any difference there is state the reset forgot or drift in the step itself.
#pragma once

#include "hapsim/core/progress.h"

#include <nlohmann/json.hpp>

#include <atomic>
#include <cstddef>
#include <filesystem>
#include <string>
#include <vector>

namespace hapsim::bench {

struct SoakOptions {
  std::filesystem::path scene;
  double duration_s = 3600.0;
  /// Reset the world before each repetition of the script (a rig: the ball back at its start).
  bool reset_between = false;
  ProgressFn progress;
  /// Stop early when this becomes true (SIGINT/SIGTERM): the result covers the steps run.
  const std::atomic<bool>* stop = nullptr;
};

struct SoakMinute {
  double p50_us = 0.0;
  double p99_us = 0.0;
  double max_us = 0.0;
  std::size_t peak_rss_bytes = 0;  ///< VmHWM at the minute's end
  std::size_t rss_bytes = 0;       ///< VmRSS at the minute's end
};

struct SoakResult {
  std::string scene;
  double script_s = 0.0;
  std::size_t repetitions = 0;
  std::size_t steps = 0;
  bool stopped = false;  ///< ended early by options.stop
  double wall_s = 0.0;
  std::vector<SoakMinute> minutes;
  /// Largest |F(t) − F_first(t)| over the tools' tip forces and finger forces, N: over every
  /// repetition, and in the last one.
  double max_force_drift_n = 0.0;
  double last_force_drift_n = 0.0;
  /// The same against the second repetition, over the third on: the first starts from a fresh
  /// world, the others from where the script left it (a script that ends elsewhere than it starts
  /// jumps back in one step), so a difference between the first two that never grows is the start,
  /// and drift is what grows after.
  double max_drift_from_second_n = 0.0;
  /// The first repetition's largest force (the scale the drift compares with).
  double peak_force_n = 0.0;
};

[[nodiscard]] SoakResult run_soak(const SoakOptions& options);
[[nodiscard]] std::string format_soak(const SoakResult& result);
[[nodiscard]] nlohmann::json soak_to_json(const SoakResult& result);

/// This process's peak and current resident set (VmHWM, VmRSS in /proc/self/status), bytes; 0
/// where unknown.
struct ProcessMemory {
  std::size_t peak_rss_bytes = 0;
  std::size_t rss_bytes = 0;
};
/// Both from one read of /proc/self/status: the kernel computes them from the same count, so the
/// peak is never below the current. (Two reads apart saw the set grow in between under ASan.)
[[nodiscard]] ProcessMemory process_memory();

}  // namespace hapsim::bench
