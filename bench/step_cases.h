// The haptic-step benchmark (issue 3's targets): the whole step — device read, collision, force,
// deformation, safety, write — on a scene's palpation, once per contact method, so each method
// stands beside the exact-query baseline in one table. Shared by `hapsim bench step` (table and
// JSON) and the Google Benchmark binary `hapsim_step_bench`.
//
// Measurement: the scene is loaded once; for each method a World is built (timed) and the scene's
// device script is run offline through run_session, which times every cycle individually with
// std::chrono::steady_clock (steady-clock overhead, ~20 ns, included). Rows report p50/p99/max.
#pragma once

#include "hapsim/core/progress.h"

#include <atomic>
#include <nlohmann/json.hpp>

#include <cstddef>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

namespace hapsim::bench {

struct StepBenchCase {
  std::string name;  // "knee-1-finger", "vhf-5-fingers"
  std::filesystem::path scene;
  /// For scenes whose meshes come from a data folder (knee_vhf.json); empty: the scene's default.
  std::optional<std::filesystem::path> data_dir;
};

/// The checkout's scenes/ folder (compiled in).
[[nodiscard]] std::filesystem::path default_scenes_dir();

/// The shipped cases: the procedural knee with one fingertip, the FEM knee with five, and (when
/// the data exists) the real VHF knee with five fingertips.
[[nodiscard]] std::vector<StepBenchCase> default_step_cases(
    const std::filesystem::path& scenes_dir, const std::optional<std::filesystem::path>& data_dir);

struct StepBenchOptions {
  std::vector<StepBenchCase> cases;
  /// "exact", "spheretree", "knee"; empty: all three.
  std::vector<std::string> methods;
  /// Simulated seconds per run; 0: the whole palpation script.
  double duration_s = 0.0;
  ProgressFn progress;
  /// Set (by SIGINT or SIGTERM) to end the bench at once: the rows done are returned
  /// (the run under way is dropped). Not owned; may be null.
  const std::atomic<bool>* stop = nullptr;
};

struct StepRow {
  std::string case_name;
  std::string method;
  std::size_t tools = 0;
  std::size_t segments = 0;
  std::size_t vertices = 0;
  std::size_t steps = 0;
  double build_ms = 0.0;
  std::size_t memory_bytes = 0;
  double p50_us = 0.0;
  double p99_us = 0.0;
  double max_us = 0.0;
  double mean_us = 0.0;
  /// Tool-steps in contact with anything (the work the step did).
  std::size_t contact_steps = 0;
  std::size_t pop_throughs = 0;
  double peak_force_n = 0.0;
  /// p50 / p99 of this row over the exact row of the same case (< 1: faster than exact).
  double p50_ratio_to_exact = 0.0;
  double p99_ratio_to_exact = 0.0;
  /// An approximate method's (knee) signed-distance error against the exact query, over
  /// kErrorPointsPerSegment points in a ±5 mm band about each segment's surface: the worst
  /// segment's p95 and the largest, metres, and the share of contacts it missed. Negative: not
  /// measured (the exact method).
  double error_p95_m = -1.0;
  double error_max_m = -1.0;
  double error_miss_rate = -1.0;
};

inline constexpr std::size_t kErrorPointsPerSegment = 2000;

[[nodiscard]] std::vector<StepRow> run_step_bench(const StepBenchOptions& options);
[[nodiscard]] std::string format_step_table(const std::vector<StepRow>& rows);
[[nodiscard]] nlohmann::json step_rows_to_json(const std::vector<StepRow>& rows);

}  // namespace hapsim::bench
