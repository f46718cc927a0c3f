#include "hapsim/net/device_state_codec.h"

#include <algorithm>

namespace hapsim::net {

// haptic path
hapsim_msg_DeviceState encode_device_state(const DeviceStateSample& s,
                                           std::uint64_t scene_hash) noexcept {
  hapsim_msg_DeviceState m{};
  m.device_id = s.device_id;
  m.state_sequence = s.sequence;
  m.scene_hash = scene_hash;
  m.device_time_s = s.input.time_s;
  for (int i = 0; i < 3; ++i) {
    m.p_m[i] = s.input.p_world[i];
    m.v_m_per_s[i] = s.v_world_m_per_s[i];
    m.rendered_force_n[i] = s.rendered.force_world_n[i];
  }
  m.q_wxyz[0] = s.input.q_world.w();
  m.q_wxyz[1] = s.input.q_world.x();
  m.q_wxyz[2] = s.input.q_world.y();
  m.q_wxyz[3] = s.input.q_world.z();
  const int fingers = std::clamp(s.input.finger_count, 0, kMaxFingers);
  m.finger_count = static_cast<std::uint16_t>(fingers);
  for (int i = 0; i < kMaxFingers; ++i) {
    const auto k = static_cast<std::size_t>(i);
    m.finger_rad[i] = s.input.finger_rad[k];
    m.rendered_finger_force_n[i] = s.rendered.finger_force_n[k];
  }
  const int joints = std::clamp(s.input.joint_count, 0, kMaxDeviceJoints);
  m.joint_count = static_cast<std::uint16_t>(joints);
  for (std::size_t j = 0; j < static_cast<std::size_t>(kMaxDeviceJoints); ++j) {
    m.joint_rad[j] = s.input.joint_rad[j];
  }
  m.buttons = s.input.buttons;
  m.healthy = s.input.healthy;
  return m;
}

// haptic path
DeviceStateSample decode_device_state(const hapsim_msg_DeviceState& m) noexcept {
  DeviceStateSample s;
  s.device_id = m.device_id;
  s.sequence = m.state_sequence;
  s.input.time_s = m.device_time_s;
  s.input.p_world = Vec3(m.p_m[0], m.p_m[1], m.p_m[2]);
  s.input.q_world = Quat(m.q_wxyz[0], m.q_wxyz[1], m.q_wxyz[2], m.q_wxyz[3]);
  s.v_world_m_per_s = Vec3(m.v_m_per_s[0], m.v_m_per_s[1], m.v_m_per_s[2]);
  s.rendered.force_world_n =
      Vec3(m.rendered_force_n[0], m.rendered_force_n[1], m.rendered_force_n[2]);
  s.input.finger_count = std::min<int>(m.finger_count, kMaxFingers);
  s.input.joint_count = std::min<int>(m.joint_count, kMaxDeviceJoints);
  for (std::size_t j = 0; j < static_cast<std::size_t>(kMaxDeviceJoints); ++j) {
    s.input.joint_rad[j] = m.joint_rad[j];
  }
  // Every finger slot travels (zero where the device has no actuator): a glove whose fingers
  // are driven by joint angles reports no finger angles, yet renders its finger forces.
  s.rendered.finger_count = kMaxFingers;
  for (int i = 0; i < kMaxFingers; ++i) {
    const auto k = static_cast<std::size_t>(i);
    s.input.finger_rad[k] = m.finger_rad[i];
    s.rendered.finger_force_n[k] = m.rendered_finger_force_n[i];
  }
  s.input.buttons = m.buttons;
  s.input.healthy = m.healthy;
  return s;
}

}  // namespace hapsim::net
