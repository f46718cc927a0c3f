// A device host's state to and from its DDS message (net/idl/hapsim_messages.idl): the input the
// simulation steps with, and the force the device actually rendered (what the simulation's
// tissue should feel, SPEC §8).
#pragma once

#include "hapsim/core/device_io.h"
#include "hapsim_messages.h"

#include <cstdint>

namespace hapsim::net {

struct DeviceStateSample {
  std::uint16_t device_id = 0;
  std::uint64_t sequence = 0;
  DeviceInput input;
  Vec3 v_world_m_per_s = Vec3::Zero();
  /// What the device rendered last cycle (tip force and per finger).
  DeviceCommand rendered;
};

/// haptic path
[[nodiscard]] hapsim_msg_DeviceState encode_device_state(const DeviceStateSample& sample,
                                                         std::uint64_t scene_hash) noexcept;
/// haptic path. Copies as is (finger_count clamped to the array); validity is the gate's.
[[nodiscard]] DeviceStateSample decode_device_state(const hapsim_msg_DeviceState& m) noexcept;

}  // namespace hapsim::net
