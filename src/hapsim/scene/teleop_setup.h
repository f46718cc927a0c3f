// A scene with a rig made runnable (000): its world with the rig added, the slave's start joints
// solved so the slave begins where the master's first pose puts it, and the master input that
// drives it (a scripted pick-and-place or tele-palpation, or a trajectory of master joints). Shared
// by `hapsim run` and the viewer, so both build exactly the same world. Here: reading the rig's
// slave (procedural or URDF) and the trajectory file, and choosing the input; the planning is in
// script/ (teleop_pick_and_place_plan.h, slave_start.h).
#pragma once

#include "hapsim/scene/scene_description.h"
#include "hapsim/script/trajectory.h"
#include "hapsim/world/world_description.h"

#include <filesystem>
#include <optional>
#include <string>

namespace hapsim {

struct TeleopSetup {
  /// The world to build: its teleoperation rig (`teleop`, slave_start_rad solved: dof() values).
  WorldDescription description;
  /// The master's input: joint_rad[0..2] arm joints, finger_rad[0..1] fingers.
  Trajectory trajectory;
  /// A pick-and-place script has a target: where the ball should come to rest (world, metres).
  bool has_target = false;
  Vec3 target_world = Vec3::Zero();
  /// For summaries: "simulated master (scripted pick-and-place)" or "... (trajectory FILE)".
  std::string device_name;
  /// "procedural Motoman" or the slave's URDF path.
  std::string slave_name;
};

/// Builds the setup of a scene with a "rig" (`scene.has_rig`): the scene's own bodies and tools
/// with the rig's pads and slave links added and the rig as the world's controller (add_rig). The
/// master plays `trajectory`, else the scene's trajectory file, else its palpation script carried
/// by the slave (the tool the rig carries presses each target; script/teleop_probe_plan.h).
/// A pick-and-place script aims at the rig's ball. `load_link_meshes`: load the URDF slave's
/// collision meshes as its links' bodies (else a box per link between joint origins). Throws
/// hapsim::Error naming the file: a URDF that does not load, a trajectory without the master's
/// columns (j0..j2, f0, f1), a script out of the master's reach or with nothing to act on (a
/// pick-and-place without a ball, a palpation without a carried tool), or a first master pose that
/// puts the slave's target out of its reach.
[[nodiscard]] TeleopSetup make_rig_setup(const SceneDescription& scene,
                                         const std::optional<std::filesystem::path>& trajectory,
                                         bool load_link_meshes);

}  // namespace hapsim
