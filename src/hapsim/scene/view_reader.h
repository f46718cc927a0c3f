// A scene's named camera views ("views" in a scene file, docs/scene-format.md#views): where a
// picture of the scene looks from, chosen by name with `--view NAME` for snapshots.
#pragma once

#include "hapsim/scene/json_reader.h"
#include "hapsim/scene/scene_description.h"

#include <string>
#include <vector>

namespace hapsim {

/// `j` (the "views" object at `ptr`: name → {eye_m, target_m, fov_deg}) as views in name order.
/// Errors name the pointer: an eye on its target, a field of view outside (1, 170] degrees, an
/// unknown key.
[[nodiscard]] std::vector<SceneView> read_views(const JsonReader& reader, const JsonReader::Json& j,
                                                const std::string& ptr);

}  // namespace hapsim
