// What joining a session needs before anything else (device host, viewers): the simulation host's
// SceneInfo, and the same world built here from its scene text (the hash must match, or the
// viewer would draw, and the simulated device aim at, another scene).
#pragma once

#include "hapsim/net/loaned_reader.h"
#include "hapsim/net/scene_info.h"
#include "hapsim/scene/run_setup.h"

#include <atomic>
#include <optional>
#include <string>

namespace hapsim::net {

/// The newest believable SceneInfo that arrived, nullopt if none since the last call. A sample
/// that is not believable is skipped, its reason in `refused` (when given).
[[nodiscard]] std::optional<SceneInfoSample> take_scene_info(
    LoanedReader<hapsim_msg_SceneInfo>& reader, std::string* refused = nullptr);

/// Polls until a SceneInfo arrives, `timeout_s` passes or `stop` is set (nullopt then).
[[nodiscard]] std::optional<SceneInfoSample> wait_for_scene_info(
    LoanedReader<hapsim_msg_SceneInfo>& reader, double timeout_s,
    const std::atomic<bool>* stop = nullptr);

/// The served scene built here, with `choice` as its device (external for a viewer, the scene's
/// script for a simulated device), from `data_dir` if given, else the host's. Throws
/// hapsim::Error ("--connect"-style, naming both hashes) when the world built here is another
/// one, and when it is a teleoperation rig (not served yet).
[[nodiscard]] RunSetup build_served_scene(const SceneInfoSample& info, const DeviceChoice& choice,
                                          const std::string& data_dir = {});

}  // namespace hapsim::net
