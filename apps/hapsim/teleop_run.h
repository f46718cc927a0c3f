// `hapsim run` for teleoperation scenes (the scene file has a "teleop" section).
#pragma once

#include "hapsim/core/progress.h"
#include "hapsim/scene/scene_description.h"

#include <filesystem>
#include <functional>
#include <limits>
#include <optional>
#include <string>

namespace hapsim {
class World;
}

namespace hapsim::app {

struct TeleopRunOptions {
  double duration_s = std::numeric_limits<double>::quiet_NaN();  // NaN: the script's length
  std::optional<std::filesystem::path> trajectory;               // --device sim:FILE
  std::string json_path;
  ProgressFn progress;
  /// Run on the real-time haptic thread (1 kHz absolute deadlines); the summary adds its figures.
  bool realtime = false;
  double spin_s = 200e-6;
  /// Called after every step with the world and the step index (1-based), and once at the end:
  /// headless snapshots. May be empty.
  std::function<void(const World& world, std::size_t step)> after_step;
  std::function<void(const World& world)> finished;
};

/// Runs the scene and prints its summary; sets exit status 1 when a pick-and-place does not end
/// with the ball within 5 mm of its target. Throws CommandError / hapsim::Error on bad input.
void run_teleop(const SceneDescription& scene, const TeleopRunOptions& options);

}  // namespace hapsim::app
