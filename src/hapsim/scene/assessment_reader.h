// A scene's "assessment" (docs/assessment.md, docs/scene-format.md "Assessment"): the landmarks a
// trainee must palpate, the safe force per tissue and a time limit. Every error is a
// hapsim::Error at "<file>:<JSON pointer>" of the offending value (an unknown segment or
// material, a negative force, a radius without a point, ...).
#pragma once

#include "hapsim/scene/scene_description.h"
#include "hapsim/scene/scene_reader.h"

#include <string>

namespace hapsim {

/// Reads the "assessment" object `j` at `ptr` into scene.assessment. A haptic-world scene's
/// bodies and materials must be read already (landmarks and limits name them); a teleoperation
/// scene (judged by its pick-and-place) takes only a time limit.
void read_assessment(const SceneReader& reader, const JsonReader::Json& j, const std::string& ptr,
                     SceneDescription& scene);

}  // namespace hapsim
