// The teleoperation scene's scripted master planned on its rig: the scene's pick-and-place
// (PickAndPlaceDescription, read by scene/device_reader.h) turned into the master's trajectory by
// script/pick_and_place_trajectory.h, picking the ball where the rig starts it with the rig's own
// gripper geometry. scene/teleop_setup.h chooses it when the scene has no trajectory file.
#pragma once

#include "hapsim/core/types.h"
#include "hapsim/kinematics/master_arm.h"
#include "hapsim/rig/rig_description.h"
#include "hapsim/script/pick_and_place_trajectory.h"
#include "hapsim/world/world_description.h"

namespace hapsim {

/// The teleoperation scene's scripted master (script/pick_and_place_trajectory.h): picks the ball
/// where it starts and places it at `place_m` (the ball's resting centre).
struct PickAndPlaceDescription {
  Vec3 place_m = Vec3(0.5, 0.25, 0.08);
  double clearance_m = 0.12;
  /// Seconds for the carry from above the ball to above the target.
  double carry_s = 2.0;
  /// Longest spacing of the script's samples, seconds. Not read from the file: 1 ms matches the
  /// haptic rate; a fuzz run that steps only the first 100 cycles coarsens it (fuzz/scene_step).
  double sample_period_s = 0.001;
};

/// The master's pick-and-place on `rig`: from the ball's start to `description.place_m`, held at
/// the depth the rig's pads and ball ask for (grasp_depth_m), opened to 0.9 of the gripper's width.
/// The plan's trajectory drives the master; the ball should come to rest at `description.place_m`.
/// Throws hapsim::Error ("pick-and-place script") when a waypoint is out of the master's reach.
[[nodiscard]] PickAndPlacePlan make_teleop_pick_and_place(
    const PickAndPlaceDescription& description, const TeleopRigDescription& rig,
    const MasterArm& master);

}  // namespace hapsim
