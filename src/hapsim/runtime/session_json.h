// The JSON of a finished session (`hapsim run --json`, `hapsim serve --json`, the Python
// module's `run()`): the same fields for a run in one process, a served one and one started from
// Python, so they can be compared key by key. Built here, below the apps, so every caller gets
// the one builder.
#pragma once

#include "hapsim/device/recording.h"
#include "hapsim/runtime/session.h"
#include "hapsim/scene/run_setup.h"
#include "hapsim/scene/scene_description.h"
#include "hapsim/world/world.h"

#include <nlohmann/json.hpp>

#include <string>
#include <vector>

namespace hapsim {

/// The `realtime` block (knee and teleop scenes alike).
[[nodiscard]] nlohmann::json realtime_json(const RealtimeSummary& rt);

/// The "fem" object of a run's JSON (FEM bodies' updates, costs and displacements); the Python
/// module's World.fem_stats() returns the same.
[[nodiscard]] nlohmann::json fem_summary_json(const FemSummary& fem);

/// Everything a session summary says, plus the scene, world and device it ran; for a rig, its
/// figures (pick-and-place, the carried tool's peak force, the master's peak joint torque).
[[nodiscard]] nlohmann::json session_summary_json(const SceneDescription& scene, const World& world,
                                                  const SessionSummary& s,
                                                  const std::string& device_name);

/// Why a finished run of `setup` failed, one line each (empty: it passed): pop-throughs, commands
/// above the device's rating, a scripted pick-and-place that missed its target. A replay's
/// difference is not among them (the caller names the recording: see run_summary_json).
[[nodiscard]] std::vector<std::string> run_failures(const RunSetup& setup,
                                                    const SessionSummary& summary);

/// The whole `hapsim run --json` document: session_summary_json, a rig's slave,
/// with `replay` (a replay's comparison with its recording) `replay_identical` and any
/// `replay_difference`, and `ok` (no run_failures and an identical replay).
[[nodiscard]] nlohmann::json run_summary_json(const RunSetup& setup, const SessionSummary& summary,
                                              const RecordingDifference* replay);

}  // namespace hapsim
