// A world made of a teleoperation rig (the teleoperation scenes): the rig as the world's controller
// (rig_controller.h), and as ordinary bodies its floor (static), sheet (deformable, Gaussian),
// ball (dynamic sphere), gripper pads (kinematic boxes) and the slave's links, palm and stem
// (kinematic: slave_shapes.h, at the slave's start joints), each with a penalty material made from
// the rig's contact springs, so the ball meets them through the same contact code as every other
// body.
#pragma once

#include "hapsim/rig/rig_description.h"
#include "hapsim/world/world_description.h"

#include <string>

namespace hapsim {

/// Throws hapsim::Error (RigController's) on a rig it cannot drive.
[[nodiscard]] WorldDescription rig_world(TeleopRigDescription rig, std::string name = "teleop");

/// A rig added to an existing world (a scene's `"rig"`, docs/scene-format.md): its gripper pads
/// and the slave's links, palm and stem appended as kinematic bodies (materials "slave_pad" and
/// "slave_link" appended), the rig as the world's controller. The rig's ball, sheet, floor and
/// carried tool are indices into `world` (or none). Throws hapsim::Error on a rig it cannot drive
/// or a material name taken.
[[nodiscard]] WorldDescription add_rig(WorldDescription world, TeleopRigDescription rig);

}  // namespace hapsim
