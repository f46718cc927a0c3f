// The older teleoperation dialect of the scene file (a top-level "teleop" section with its ball,
// sheet and floor built in; docs/scene-format.md, "Older teleop scenes"), converted on read into
// the one scene language: the ball, the sheet and the floor become ordinary bodies with their
// materials, the slave, mapping and gripper a "rig" that names them. Errors name the old file's
// own JSON pointers: the old sections are checked before they are converted.
#pragma once

#include "hapsim/scene/scene_reader.h"

#include <string>

namespace hapsim {

/// The note a converted file carries (SceneDescription::warnings): said once, where a user reads.
[[nodiscard]] std::string teleop_dialect_note(const std::string& file);

/// `root`, a scene with a "teleop" section, as the same scene in the one language ("materials",
/// "bodies", "rig"); "device", "run", "views" and "assessment" carry over as they are.
[[nodiscard]] JsonReader::Json convert_teleop_scene(const SceneReader& reader,
                                                    const JsonReader::Json& root);

}  // namespace hapsim
