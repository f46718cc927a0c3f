// What a haptic device gives the simulation each cycle, and what the simulation sends back.
// Plain fixed-size data (no allocation), shared by World::step, the devices, the recorder and
// the network layer.
#pragma once

#include "hapsim/core/types.h"

#include <array>
#include <cstdint>

namespace hapsim {

inline constexpr int kMaxFingers = 5;
inline constexpr int kMaxDeviceJoints = 16;

/// One cycle of device input, in the device's world frame (metres, radians).
struct DeviceInput {
  double time_s = 0.0;
  /// Tool / stylus / tracker pose: position and orientation.
  Vec3 p_world = Vec3::Zero();
  Quat q_world = Quat::Identity();
  /// Joint angles of an arm-type device (master arm), radians; `joint_count` used.
  std::array<double, kMaxDeviceJoints> joint_rad{};
  int joint_count = 0;
  /// Finger flexion per finger for a glove (radians), or grasp opening for a stylus/gripper.
  std::array<double, kMaxFingers> finger_rad{};
  int finger_count = 0;
  /// Button bits (bit 0 = primary).
  std::uint32_t buttons = 0;
  /// False when the device reports itself unhealthy or the link dropped.
  bool healthy = true;
};

/// One cycle of output to the device (newtons, world frame).
struct DeviceCommand {
  /// Force on the tool / stylus tip.
  Vec3 force_world_n = Vec3::Zero();
  /// Force per finger actuator (a force glove has one per finger), newtons, >= 0.
  std::array<double, kMaxFingers> finger_force_n{};
  int finger_count = 0;
  /// Joint torques for arm-type devices, N·m.
  std::array<double, kMaxDeviceJoints> joint_torque_nm{};
  int joint_count = 0;
};

}  // namespace hapsim
