// The teleoperation branch of a scene file (docs/scene-format.md, "Teleoperation scenes"): the
// "teleop" section (slave arm, master-to-slave mapping, gripper, ball, sheet, floor) and the
// master device that drives it (a trajectory CSV of master joints or a pick-and-place script).
// Every error is a hapsim::Error at "<file>:<JSON pointer>" of the offending value.
#pragma once

#include "hapsim/scene/scene_description.h"
#include "hapsim/scene/scene_reader.h"

#include <string>

namespace hapsim {

/// Reads the "teleop" object `j` at `ptr` into `t` (absent keys keep t's defaults).
void read_teleop(const SceneReader& reader, const JsonReader::Json& j, const std::string& ptr,
                 TeleopSceneDescription& t);

/// Reads a scene's "rig" object `j` at `ptr` (docs/scene-format.md, "Rigs"): the slave, the
/// mapping, the gripper, the force scale and the names of the scene's bodies and tool it drives or
/// reads (its ball, sheet, floor, the tool it carries), checked against `scene.world`, which must
/// be read first. Sets scene.has_rig.
void read_rig(const SceneReader& reader, const JsonReader::Json& j, const std::string& ptr,
              SceneDescription& scene);
/// Reads a teleoperation scene's "device" object `j` at `ptr` into `d` (profile "simulated").
void read_teleop_device(const SceneReader& reader, const JsonReader::Json& j,
                        const std::string& ptr, DeviceDescription& d);

}  // namespace hapsim
