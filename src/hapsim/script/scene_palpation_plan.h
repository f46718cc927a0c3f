// A scene's scripted palpation planned on its world: each target the scene file names
// (PalpationScriptDescription, read by scene/device_reader.h) aimed at its first surface
// (script/palpation_aim.h) and pressed by the world's first tool, moves between targets round the
// body when the script gives an axis (script/palpation_trajectory.h makes the motion).
#pragma once

#include "hapsim/core/types.h"
#include "hapsim/script/palpation_aim.h"
#include "hapsim/script/palpation_trajectory.h"

#include <vector>

namespace hapsim {

class World;

struct PalpationScriptDescription {
  std::vector<PalpationTargetDescription> targets;
  double standoff_m = 0.02;
  double move_s = 1.0;
  double approach_s = 0.5;
  double press_s = 0.5;
  double release_s = 0.5;
  /// Moves between targets go round this axis (through the body's centre) on a cylinder that
  /// clears the body and the tools, instead of straight through the body. Optional.
  bool has_around_axis = false;
  Vec3 around_axis_world = Vec3::UnitZ();
  /// Longest spacing of the script's samples, seconds. Not read from the file: 1 ms matches the
  /// haptic rate; a fuzz run that steps only the first 100 cycles coarsens it (fuzz/scene_step).
  double sample_period_s = 0.001;
};

/// The scripted palpation of a scene, for its first tool's centre (the device point): each
/// target is pressed `depth_m` past the point where the tool sphere touches the surface.
[[nodiscard]] PalpationPlan make_scene_palpation(const World& world,
                                                 const PalpationScriptDescription& script);

}  // namespace hapsim
