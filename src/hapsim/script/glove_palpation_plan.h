// A scene's scripted glove palpation planned on its world (the knee paper's hand variant): each
// chosen fingertip's press aimed at its own segment (script/palpation_aim.h), the hand turned and
// posed so all of them reach at once (script/hand_pose.h), and the hand brought in, pressed, held
// and backed off. The scene file names the targets (scene/device_reader.h).
#pragma once

#include "hapsim/core/types.h"
#include "hapsim/script/trajectory.h"

#include <optional>
#include <string>
#include <vector>

namespace hapsim {

class World;

/// One finger of a glove palpation: the finger (0 thumb .. 4 little) presses the named segment,
/// or the body's surface over `toward_world` (a FEM body has no segments to name).
struct GloveFingerTarget {
  int finger = 1;
  std::string body;
  std::string segment;
  std::optional<Vec3> toward_world;
};

/// A scripted glove palpation (knee paper §3.1, the hand variant): the hand comes at the body from
/// `from_world` with its fingers formed so each chosen fingertip lands on its own segment, presses
/// `depth_m` in, holds and backs off; fingers not chosen stay curled out of the way.
struct GlovePalpationDescription {
  std::vector<GloveFingerTarget> fingers;
  Vec3 from_world = Vec3::UnitY();
  double depth_m = 0.006;
  double standoff_m = 0.03;
  double move_s = 0.8;
  double press_s = 0.6;
  double hold_s = 0.6;
  double release_s = 0.6;
  /// Longest spacing of the script's samples, seconds. Not read from the file: 1 ms matches the
  /// haptic rate; a fuzz run that steps only the first 100 cycles coarsens it (fuzz/scene_step).
  double sample_period_s = 0.001;
};

/// The scripted glove palpation of a scene: the hand's orientation puts its back towards `from`
/// and its finger spread along the line between the first two targets; its position and each
/// chosen finger's angles (abduction, MCP, PIP; DIP coupled) are solved so every chosen
/// fingertip sphere presses `depth_m` into its own segment's aimed surface point, the other
/// fingers curled away. The hand comes in along −from, presses, holds and backs off. Throws
/// hapsim::Error ("glove palpation") when a finger cannot reach its target from that hand pose.
[[nodiscard]] Trajectory make_scene_glove_palpation(const World& world,
                                                    const GlovePalpationDescription& script);

}  // namespace hapsim
