// The "device" of a haptic-world scene file (docs/scene-format.md, "Device", "Glove", "Palpation
// script"): its type and profile, and what drives it — a trajectory CSV, a palpation script
// aimed at named segments, or, for a glove, the hand's settings and a glove palpation; for a
// scene with a "rig", its master arm (a trajectory, a pick-and-place or a palpation). Every error
// is a hapsim::Error at "<file>:<JSON pointer>" of the offending value.
#pragma once

#include "hapsim/scene/scene_description.h"
#include "hapsim/scene/scene_reader.h"

#include <string>

namespace hapsim {

/// Reads the device object `j` at `ptr` into scene.device; a glove also sets the world's hand
/// (scene.world.has_hand, hand). The world's tools and bodies must be read already: fingers are
/// checked against the profile and the tools, glove palpation targets against the bodies.
void read_device(const SceneReader& reader, const JsonReader::Json& j, const std::string& ptr,
                 SceneDescription& scene);

/// Every palpation target of scene.device names a body of scene.world and one of its segments;
/// else an error at /device/palpation/targets/<i>/body or …/segment.
void check_palpation_targets(const SceneReader& reader, const SceneDescription& scene);

}  // namespace hapsim
