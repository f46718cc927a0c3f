// What a teleoperation rig did in one step (rig_controller.h): its command to the master, the
// slave's motion, the gripper, and the report on the ball, the grasp and the sheet.
#pragma once

#include "hapsim/core/device_io.h"
#include "hapsim/core/types.h"
#include "hapsim/kinematics/serial_chain.h"
#include "hapsim/kinematics/slave_follower.h"
#include "hapsim/rig/ball_environment.h"
#include "hapsim/rig/parallel_gripper.h"

#include <array>
#include <cstdint>

namespace hapsim {

/// What a teleoperation rig did this step (rig_description.h: TeleopRigDescription).
struct TeleopStepResult {
  double time_s = 0.0;
  /// What the master's motors get (arm joint torques, finger torques as joints 3 and 4).
  DeviceCommand command;
  /// The master's arm joints (base, shoulder, elbow) and fingers, radians, and its hand pose in
  /// its base frame: from the last usable input (held through an unusable one).
  std::array<double, 3> master_arm_rad{};
  std::array<double, 2> master_finger_rad{};
  Iso3 master_hand = Iso3::Identity();
  Iso3 slave_tool = Iso3::Identity();
  SlaveStep slave;
  GripperReport gripper;
  BallContactReport ball_contacts;
  Vec3 ball_p_world = Vec3::Zero();
  bool held = false;
  double sheet_depth_m = 0.0;
  /// Place stage: pairs (slave body, static or deformable body) in contact this step — a link,
  /// the palm, the stem or a pad more than RigState::kCollisionDepthM inside the floor, the sheet
  /// or another body that cannot be pushed back: where the real robot would hit the table.
  std::int32_t slave_collisions = 0;
  /// Which bodies they were, a bit per body index (< 64): the slave's and the others.
  std::uint64_t slave_collision_bodies = 0;
  /// The force on the slave's tool this step, world frame: the pads' and the gripper's reaction
  /// and the carried tool's contact force (what the master's hand feels, before the scale).
  Vec3 tool_force_world_n = Vec3::Zero();
  /// What the slave's joints hold against it: τ = J_slaveᵀ·[F; (p_tool − p_flange) × F] with the
  /// carried tool's force F at its centre, N·m (slave dof() entries; the rest 0).
  std::array<double, static_cast<std::size_t>(kMaxChainJoints)> slave_joint_torque_nm{};
};

}  // namespace hapsim
