// What a simulation host tells everyone who joins its session (net/idl SceneInfo, reliable and
// transient-local): which scene it runs (its content hash, and its file's text so a viewer or a
// simulated device can rebuild it), at what rate, for which device, and which start of the host
// it is (serve_id: a restarted host numbers its models from 1 again, so a device host must know
// it is a new one). Off the haptic path.
#pragma once

#include "hapsim_messages.h"

#include <array>
#include <cstdint>
#include <optional>
#include <string>

namespace hapsim::net {

struct SceneInfoSample {
  std::uint64_t scene_hash = 0;
  std::uint64_t serve_id = 0;
  double rate_hz = 1000.0;
  std::uint16_t device_id = 0;
  std::uint16_t tool_count = 0;
  /// Per tool: the device finger it is (-1: the device's tip), as the scene says.
  std::array<std::int16_t, 5> tool_finger{-1, -1, -1, -1, -1};
  std::string scene_file;
  std::string scene_json;
  std::string data_dir;
};

/// The largest scene text accepted (a scene file names its meshes; it does not hold them).
inline constexpr std::size_t kMaxSceneJsonBytes = 4u << 20;

/// A message pointing into `sample`'s strings (valid while `sample` lives and is unchanged).
[[nodiscard]] hapsim_msg_SceneInfo scene_info_message(const SceneInfoSample& sample);

/// The sample in `m`, or nullopt with `why` set when it is not believable (a null or oversized
/// string, a rate outside 10-10000 Hz, more tools than a device has fingers, a zero serve id).
[[nodiscard]] std::optional<SceneInfoSample> decode_scene_info(const hapsim_msg_SceneInfo& m,
                                                               std::string& why);

/// A fresh, non-zero serve id (from the system's random source and the clock).
[[nodiscard]] std::uint64_t draw_serve_id();

}  // namespace hapsim::net
