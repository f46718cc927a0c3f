// A rig in a world (architecture.md#controllers): add_rig() appends the rig's gripper pads
// (kinematic boxes) and the slave's links, palm and stem (kinematic: slave_shapes.h, at the
// slave's start joints) to any world and makes the rig its controller (rig_controller.h). A scene
// with a "rig" is built so (scene/teleop_setup.h). rig_world() builds the first paper's
// pick-and-place world in code, for tests and benchmarks: its floor (static), sheet (deformable,
// Gaussian) and ball (dynamic, rigid) as ordinary bodies with penalty materials from the rig's
// contact springs, the rig added. scenes/teleop.json is the same world as a scene.
#pragma once

#include "hapsim/rig/rig_description.h"
#include "hapsim/world/world_description.h"

#include <string>

namespace hapsim {

/// The pick-and-place world of `rig` (its ball, sheet and floor options) with the rig added; the
/// rig's ball, sheet and floor indices are set here. Throws hapsim::Error (RigController's) on a
/// rig it cannot drive.
[[nodiscard]] WorldDescription rig_world(TeleopRigDescription rig, std::string name = "teleop");

/// A rig added to an existing world (a scene's `"rig"`, docs/scene-format.md): its gripper pads
/// and the slave's links, palm and stem appended as kinematic bodies (materials "slave_pad" and
/// "slave_link" appended), the rig as the world's controller. The rig's ball, sheet, floor and
/// carried tool are indices into `world` (or none). Throws hapsim::Error on a rig it cannot drive
/// or a material name taken.
[[nodiscard]] WorldDescription add_rig(WorldDescription world, TeleopRigDescription rig);

}  // namespace hapsim
