// What the viewer (and later the network) sees of a teleoperation rig beyond its bodies (the ball,
// the sheet, the pads and the slave's links are the WorldSnapshot's, as every body is): the
// newest cycle's master input and command, the slave's joints and tool, the gripper; the rig's
// part of a WorldSnapshot, published by the world's haptic client through its triple
// buffer (world_haptic_client.h).
// Sized once for a world, so filling one never allocates.
#pragma once

#include "hapsim/world/world.h"

#include <array>
#include <cstdint>
#include <vector>

namespace hapsim {

struct TeleopSnapshot {
  std::uint64_t cycle = 0;
  double time_s = 0.0;
  DeviceInput input;
  /// What the master was sent (after safety).
  DeviceCommand output;
  /// The master's arm joints (base, shoulder, elbow) and finger angles, radians: the last usable
  /// input (what the world followed).
  std::array<double, 3> master_joint_rad{};
  std::array<double, 2> master_finger_rad{};
  /// The master's hand in its base frame.
  Iso3 X_master_hand = Iso3::Identity();
  /// The slave's joints (dof() values), radians or metres.
  std::vector<double> slave_q;
  /// The slave's tool (flange) pose in the world (the slave's base frame is the world).
  Iso3 X_world_tool = Iso3::Identity();
  /// Pad opening reached, metres, and each pad's normal force on the ball, newtons.
  double gripper_width_m = 0.0;
  std::array<double, 2> pad_force_n{};
  /// (N₁ + N₂) / 2: what the master's fingers feel, newtons.
  double grasp_force_n = 0.0;
  bool held = false;
  /// The sheet's deepest dent (its surface and the ball's pose are the WorldSnapshot's, as every
  /// body's), metres.
  double sheet_depth_m = 0.0;
};

/// A snapshot sized for `world` (which must have a teleoperation rig), holding its current state.
[[nodiscard]] TeleopSnapshot make_teleop_snapshot(const World& world);

/// Copies the world's current state into `snapshot` (sized by make_teleop_snapshot for the same
/// world); leaves cycle, time_s, input and output to the caller. haptic path (no allocation)
void fill_teleop_snapshot(TeleopSnapshot& snapshot, const World& world) noexcept;

}  // namespace hapsim
