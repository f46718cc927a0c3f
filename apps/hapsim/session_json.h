// The JSON of a finished session (`hapsim run --json`, `hapsim serve --json`): the same fields
// for a run in one process and a served one, so the two can be compared key by key.
#pragma once

#include "hapsim/runtime/session.h"
#include "hapsim/scene/scene_description.h"
#include "hapsim/world/world.h"

#include <nlohmann/json.hpp>

#include <string>

namespace hapsim::app {

/// The `realtime` block (knee and teleop scenes alike).
[[nodiscard]] nlohmann::json realtime_json(const RealtimeSummary& rt);

/// Everything a session summary says, plus the scene, world and device it ran.
[[nodiscard]] nlohmann::json session_summary_json(const SceneDescription& scene, const World& world,
                                                  const SessionSummary& s,
                                                  const std::string& device_name);

}  // namespace hapsim::app
