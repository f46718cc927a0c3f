// `hapsim bench contact` (issue 30): contact that holds at hand speed. A fingertip pressed into
// the skin over each knee landmark (and the middle of a 2 mm plate) until it pushes back firmly
// (4 N) (patella, tibial tuberosity,
// patellar tendon, MCL, LCL: thin or curved parts over bone, ligament and tendon) is dragged 30 mm
// to each side across it and back, at 10 to 500 mm/s, then held over it; per scene, landmark,
// contact method and speed: pop-throughs (a proxy lost with the tool inside its body counts as
// one), the largest force change between two cycles while dragging (force continuity), and the
// haptic step's cost (World::step only; a FEM body's updates run between cycles, untimed, as
// `hapsim run` does on its own thread).
#pragma once

#include "hapsim/core/progress.h"

#include <atomic>
#include <nlohmann/json.hpp>

#include <filesystem>
#include <string>
#include <vector>

namespace hapsim::bench {

struct ContactBenchOptions {
  /// Scene files (default: the paper's knee, the FEM knee and the 2 mm plate in the checkout's
  /// scenes/); each runs the landmarks that belong to it.
  std::vector<std::filesystem::path> scenes;
  /// exact, spheretree, knee (default: all three; a method a scene cannot use is reported).
  std::vector<std::string> methods;
  std::vector<double> speeds_mm_per_s{10.0, 50.0, 200.0, 500.0};
  /// Landmark names (default: all: the knee's five, the plate's one).
  std::vector<std::string> landmarks;
  /// The fingertip is pressed in until the force reaches this (a firm palpation), or
  /// `max_depth_mm` past the first touch of the skin, before the drag.
  double press_n = 4.0;
  double max_depth_mm = 15.0;
  ProgressFn progress;
  /// Set (by SIGINT or SIGTERM) to end the bench after the row under way: the rows done are
  /// returned. Not owned; may be null.
  const std::atomic<bool>* stop = nullptr;
};

struct ContactRow {
  std::string scene;
  std::string landmark;
  std::string method;
  double speed_mm_per_s = 0.0;
  std::string error;  ///< non-empty: the case could not run (the rest is empty)
  /// How far past the first touch of the skin the drag runs, mm.
  double depth_mm = 0.0;
  std::size_t steps = 0;
  std::size_t pop_throughs = 0;
  /// While dragging: the largest |F(k) − F(k−1)|, and its 99th percentile, N.
  double max_force_jump_n = 0.0;
  double p99_force_jump_n = 0.0;
  double peak_force_n = 0.0;
  /// The force when held over the landmark after the drags, N.
  double held_force_n = 0.0;
  double step_p50_us = 0.0;
  double step_p99_us = 0.0;
  double step_max_us = 0.0;
};

[[nodiscard]] std::vector<std::string> contact_landmark_names();
[[nodiscard]] std::vector<ContactRow> run_contact_bench(const ContactBenchOptions& options);
[[nodiscard]] std::string format_contact_table(const std::vector<ContactRow>& rows);
[[nodiscard]] nlohmann::json contact_rows_to_json(const std::vector<ContactRow>& rows);

}  // namespace hapsim::bench
