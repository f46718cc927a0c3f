#include "hapsim/net/scene_info.h"

#include "hapsim/core/device_io.h"

#include <chrono>
#include <cmath>
#include <cstring>
#include <random>

namespace hapsim::net {

hapsim_msg_SceneInfo scene_info_message(const SceneInfoSample& s) {
  hapsim_msg_SceneInfo m{};
  m.scene_hash = s.scene_hash;
  m.serve_id = s.serve_id;
  m.rate_hz = s.rate_hz;
  m.device_id = s.device_id;
  m.tool_count = s.tool_count;
  for (std::size_t t = 0; t < s.tool_finger.size(); ++t) {
    m.tool_finger[t] = s.tool_finger[t];
  }
  // The generated type holds char*; dds_write only reads them.
  m.scene_file = const_cast<char*>(s.scene_file.c_str());
  m.scene_json = const_cast<char*>(s.scene_json.c_str());
  m.data_dir = const_cast<char*>(s.data_dir.c_str());
  return m;
}

std::optional<SceneInfoSample> decode_scene_info(const hapsim_msg_SceneInfo& m, std::string& why) {
  if (m.scene_file == nullptr || m.scene_json == nullptr || m.data_dir == nullptr) {
    why = "a string is missing";
    return std::nullopt;
  }
  const std::size_t json_bytes = std::strlen(m.scene_json);
  if (json_bytes == 0 || json_bytes > kMaxSceneJsonBytes) {
    why = "scene text of " + std::to_string(json_bytes) + " bytes (expected 1 to " +
          std::to_string(kMaxSceneJsonBytes) + ")";
    return std::nullopt;
  }
  if (!(std::isfinite(m.rate_hz) && m.rate_hz >= 10.0 && m.rate_hz <= 10'000.0)) {
    why = "rate " + std::to_string(m.rate_hz) + " Hz (expected 10 to 10000)";
    return std::nullopt;
  }
  if (m.tool_count > kMaxFingers) {
    why = std::to_string(m.tool_count) + " tools (at most " + std::to_string(kMaxFingers) + ")";
    return std::nullopt;
  }
  if (m.serve_id == 0) {
    why = "serve id 0";
    return std::nullopt;
  }
  for (std::size_t t = 0; t < m.tool_count; ++t) {
    if (m.tool_finger[t] < -1 || m.tool_finger[t] >= kMaxFingers) {
      why = "tool " + std::to_string(t) + " is finger " + std::to_string(m.tool_finger[t]);
      return std::nullopt;
    }
  }
  SceneInfoSample s;
  for (std::size_t t = 0; t < s.tool_finger.size(); ++t) {
    s.tool_finger[t] = t < m.tool_count ? m.tool_finger[t] : std::int16_t{-1};
  }
  s.scene_hash = m.scene_hash;
  s.serve_id = m.serve_id;
  s.rate_hz = m.rate_hz;
  s.device_id = m.device_id;
  s.tool_count = m.tool_count;
  s.scene_file = m.scene_file;
  s.scene_json.assign(m.scene_json, json_bytes);
  s.data_dir = m.data_dir;
  return s;
}

std::uint64_t draw_serve_id() {
  std::random_device device;
  std::uint64_t id =
      (static_cast<std::uint64_t>(device()) << 32) ^ device() ^
      static_cast<std::uint64_t>(std::chrono::steady_clock::now().time_since_epoch().count());
  return id == 0 ? 1 : id;
}

}  // namespace hapsim::net
