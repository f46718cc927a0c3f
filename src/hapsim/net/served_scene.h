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
#include <vector>

namespace hapsim::net {

/// The newest believable SceneInfo that arrived, nullopt if none since the last call. A sample
/// that is not believable is skipped, its reason in `refused` (when given).
[[nodiscard]] std::optional<SceneInfoSample> take_scene_info(
    LoanedReader<hapsim_msg_SceneInfo>& reader, std::string* refused = nullptr);

/// Polls until a SceneInfo arrives, `timeout_s` passes or `stop` is set (nullopt then).
[[nodiscard]] std::optional<SceneInfoSample> wait_for_scene_info(
    LoanedReader<hapsim_msg_SceneInfo>& reader, double timeout_s,
    const std::atomic<bool>* stop = nullptr);

/// One user's device host in a served scene (SceneInfo's text): its name, its device id (the
/// serve's first one plus its place among the scene's hosts) and its tools (at most kMaxFingers,
/// as serve keys their models).
struct ServedDeviceHost {
  std::string name;
  std::uint16_t device_id = 0;
  std::vector<std::string> tool_names;
  std::vector<int> tool_finger;  ///< per tool, -1: the tip
};

/// The device hosts the served scene's tools name ("device_host"), in the scene's order; empty
/// for a one-user scene. Reads the scene's text only (no mesh is loaded). Throws hapsim::Error
/// when the text does not parse.
[[nodiscard]] std::vector<ServedDeviceHost> served_device_hosts(const SceneInfoSample& info);

/// The served scene built here, with `choice` as its device (external for a viewer, the scene's
/// script for a simulated device), from `data_dir` if given, else the host's. Throws
/// hapsim::Error ("--connect"-style, naming both hashes) when the world built here is another
/// one.
[[nodiscard]] RunSetup build_served_scene(const SceneInfoSample& info, const DeviceChoice& choice,
                                          const std::string& data_dir = {});

}  // namespace hapsim::net
