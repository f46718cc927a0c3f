// Shared by the network tests: the loopback guard and a deterministic local-model message.
#pragma once

#include "hapsim/net/local_model_codec.h"

#include <cstdlib>
#include <cstring>
#include <regex>
#include <string>

#include <gtest/gtest.h>

namespace hapsim::net::test {

/// Every DDS test runs on the shipped loopback config (ctest sets CYCLONEDDS_URI): refuse to
/// start otherwise, so a test never multicasts on the machine's real interface.
inline ::testing::AssertionResult on_loopback_config() {
  const char* uri = std::getenv("CYCLONEDDS_URI");
  const std::string expected = std::string("file://") + HAPSIM_DDS_CONFIG;
  if (uri == nullptr || expected != uri) {
    return ::testing::AssertionFailure() << "CYCLONEDDS_URI must be " << expected
                                         << " (run through ctest), is " << (uri ? uri : "unset");
  }
  return ::testing::AssertionSuccess();
}

/// Why serve's forces cannot be compared with the one-process run's, or "" when they can. Serve
/// keeps its 1 kHz only if the machine runs its step and its peers in time; where serve simulated
/// under 0.9 s per wall-clock second (Debug ASan: 0.4x with a step of 1.8 ms, 0.6x with the
/// device host's processes on two busy cores) its loop is late, ramps the force after each gap,
/// and renders something else. Read from serve's summary ("N steps, S s simulated in W s wall");
/// a release build keeps 1.0x. (Not the step cost: with a device host driving it, serve's step
/// includes the wait for the device's state, 0.5 ms in release.)
/// Serve's pace, simulated seconds per wall-clock second, from its summary ("N steps, S s
/// simulated in W s wall"); 0 when the summary is missing.
inline double serve_pace(const std::string& serve_output) {
  static const std::regex kPace(R"(([0-9.]+) s simulated in ([0-9.]+) s wall)");
  std::smatch m;
  if (!std::regex_search(serve_output, m, kPace) || !(std::stod(m[2].str()) > 0.0)) {
    return 0.0;
  }
  return std::stod(m[1].str()) / std::stod(m[2].str());
}

inline std::string serve_too_slow_for_real_time(const std::string& serve_output) {
  static const std::regex kPace(R"(([0-9.]+) s simulated in ([0-9.]+) s wall)");
  std::smatch m;
  if (std::regex_search(serve_output, m, kPace) && std::stod(m[2].str()) > 0.0 &&
      std::stod(m[1].str()) / std::stod(m[2].str()) < 0.9) {
    return "serve simulated " + m[1].str() + " s in " + m[2].str() +
           " s of wall-clock time: this machine or build could not keep it in real time, so its "
           "rates and forces are not the scene's";
  }
  return {};
}

inline constexpr std::uint64_t kSceneHash = 0x68617073696d2121ULL;
inline constexpr std::uint16_t kDeviceId = 3;

/// A model whose every field is a distinct function of `sequence` (so a swapped, truncated or
/// stale field shows up), valid for the gate's default limits.
inline LocalContactModel model_for(std::uint64_t sequence) {
  const double s = static_cast<double>(sequence);
  LocalContactModel m;
  m.x0_world_m = Vec3(0.001 * s, -0.002 * s, 0.1 + 1e-7 * s) / 1000.0;
  m.v0_world_m_per_s = Vec3(0.01, -0.02 + 1e-6 * s, 0.03);
  m.f0_world_n = Vec3(0.0, 0.0, 1.0 + 1e-3 * s);
  m.stiffness_n_per_m << 500.0 + s * 1e-3, 1.0, 2.0, 1.0, 600.0, 3.0, 2.0, 3.0, 700.0;
  m.damping_n_s_per_m = Mat3::Identity() * (0.5 + 1e-9 * s);
  m.normal_world = Vec3(0.0, 0.0, 1.0);
  m.validity_radius_m = 0.01;
  m.sim_time_s = 1e-3 * s;
  m.sequence = sequence;
  m.device_sequence = sequence;
  m.valid = true;
  return m;
}

inline hapsim_msg_LocalModel message_for(std::uint64_t sequence) {
  return encode_local_model(model_for(sequence), {kDeviceId, 0}, kSceneHash);
}

/// Field by field, bit for bit (the struct's padding bytes are not part of the sample).
inline bool same_bits(const hapsim_msg_LocalModel& a, const hapsim_msg_LocalModel& b) {
  const auto eq = [](const auto& x, const auto& y) { return std::memcmp(&x, &y, sizeof x) == 0; };
  return a.device_id == b.device_id && a.finger == b.finger &&
         a.model_sequence == b.model_sequence && a.device_sequence == b.device_sequence &&
         a.scene_hash == b.scene_hash && eq(a.sim_time_s, b.sim_time_s) && eq(a.x0_m, b.x0_m) &&
         eq(a.v0_m_per_s, b.v0_m_per_s) && eq(a.f0_n, b.f0_n) &&
         eq(a.stiffness_n_per_m, b.stiffness_n_per_m) &&
         eq(a.damping_n_s_per_m, b.damping_n_s_per_m) && eq(a.normal, b.normal) &&
         eq(a.validity_radius_m, b.validity_radius_m) && a.valid == b.valid &&
         eq(a.max_normal_force_n, b.max_normal_force_n) && a.profile_count == b.profile_count &&
         eq(a.profile_depth_m, b.profile_depth_m) && eq(a.profile_push_n, b.profile_push_n);
}

}  // namespace hapsim::net::test
