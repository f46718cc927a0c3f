// A scene's "rig" (docs/scene-format.md, "Rigs"): the slave arm, the master-to-slave mapping, the
// gripper, the force scale, and the names of the scene's bodies and tool the rig drives or reports
// on. Every error is a hapsim::Error at "<file>:<JSON pointer>" of the offending value.
#pragma once

#include "hapsim/scene/scene_description.h"
#include "hapsim/scene/scene_reader.h"

#include <string>

namespace hapsim {

/// Reads the arm of a rig object `j` at `ptr` into `t`: "slave" (a procedural model or a URDF and
/// its tip), "mapping" and "gripper"; absent keys keep t's defaults. Shared with the older
/// "teleop" dialect (teleop_dialect.h), which checks its own file with it.
void read_rig_arm(const SceneReader& reader, const JsonReader::Json& j, const std::string& ptr,
                  TeleopSceneDescription& t);

/// Reads a scene's "rig" object `j` at `ptr`: the arm, the force scale and the names of the scene's
/// bodies and tool it drives or reads (its ball, a dynamic sphere; sheet; floor; the tool it
/// carries), checked against `scene.world`, which must be read first. Sets scene.has_rig.
void read_rig(const SceneReader& reader, const JsonReader::Json& j, const std::string& ptr,
              SceneDescription& scene);

}  // namespace hapsim
