#include "hapsim/net/served_scene.h"

#include "hapsim/core/error.h"
#include "hapsim/net/scene_hash.h"
#include "hapsim/scene/scene_file.h"

#include <chrono>
#include <cinttypes>
#include <cstdio>
#include <thread>

namespace hapsim::net {

namespace {

std::string hex(std::uint64_t value) {
  char text[24];
  std::snprintf(text, sizeof text, "%016" PRIx64, value);
  return text;
}

}  // namespace

std::optional<SceneInfoSample> take_scene_info(LoanedReader<hapsim_msg_SceneInfo>& reader,
                                               std::string* refused) {
  std::optional<SceneInfoSample> newest;
  reader.take([&](const hapsim_msg_SceneInfo& m) {
    std::string why;
    if (auto info = decode_scene_info(m, why)) {
      newest = std::move(info);
    } else if (refused != nullptr) {
      *refused = why;
    }
  });
  return newest;
}

std::optional<SceneInfoSample> wait_for_scene_info(LoanedReader<hapsim_msg_SceneInfo>& reader,
                                                   double timeout_s,
                                                   const std::atomic<bool>* stop) {
  const auto give_up = std::chrono::steady_clock::now() +
                       std::chrono::duration_cast<std::chrono::steady_clock::duration>(
                           std::chrono::duration<double>(std::min(timeout_s, 1e9)));
  for (;;) {
    if (auto info = take_scene_info(reader)) {
      return info;
    }
    if (std::chrono::steady_clock::now() > give_up ||
        (stop != nullptr && stop->load(std::memory_order_relaxed))) {
      return std::nullopt;
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
  }
}

std::vector<ServedDeviceHost> served_device_hosts(const SceneInfoSample& info) {
  SceneLoadOptions load;
  load.device_trajectory_played = false;  // only the tools are read
  if (!info.data_dir.empty()) {
    load.data_dir = info.data_dir;
  }
  const SceneDescription scene = parse_scene(info.scene_json, info.scene_file, load);
  const WorldDescription& world = scene.world;
  std::vector<ServedDeviceHost> hosts(world.device_hosts.size());
  for (std::size_t k = 0; k < hosts.size(); ++k) {
    hosts[k].name = world.device_hosts[k];
    hosts[k].device_id = static_cast<std::uint16_t>(info.device_id + k);
  }
  for (const ToolDescription& tool : world.tools) {
    const auto k = static_cast<std::size_t>(tool.device);
    if (k < hosts.size() && hosts[k].tool_names.size() < static_cast<std::size_t>(kMaxFingers)) {
      hosts[k].tool_names.push_back(tool.name);
      hosts[k].tool_finger.push_back(tool.finger);
    }
  }
  return hosts;
}

RunSetup build_served_scene(const SceneInfoSample& info, const DeviceChoice& choice,
                            const std::string& data_dir) {
  SceneLoadOptions load;
  const std::string folder = !data_dir.empty() ? data_dir : info.data_dir;
  if (!folder.empty()) {
    load.data_dir = folder;
  }
  RunSetup setup = make_run_setup(parse_scene(info.scene_json, info.scene_file, load), choice);
  const std::uint64_t ours = scene_hash(setup.world->content_hash());
  if (ours != info.scene_hash) {
    throw Error(info.scene_file, "the scene built here (hash " + hex(ours) +
                                     ") is not the one served (hash " + hex(info.scene_hash) +
                                     "): give this machine the host's data folder (--data)");
  }
  return setup;
}

}  // namespace hapsim::net
