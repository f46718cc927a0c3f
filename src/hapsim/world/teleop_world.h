// The teleoperation world of the first paper (000): a 5-DOF master arm drives a Motoman slave with
// a parallel gripper; the slave picks a rigid ball and places it on the virtual sheet, which
// deforms under it and takes its imprint. One step, a pure function of state and master input:
//   master joints (joint_rad[0..2]) and fingers (finger_rad[0..1])
//   → master hand pose → scaled slave target → slave IK, joints at their speed limits
//   → gripper pads vs ball (grasp / release) → ball dynamics on the sheet and floor
//   → forces back: the grasp force on the master's fingers, the contact force at the slave's
//     tool (scaled back) on the master's arm through Jᵀ, clamped per motor.
// Allocation-free after construction.
#pragma once

#include "hapsim/core/device_io.h"
#include "hapsim/deform/virtual_sheet.h"
#include "hapsim/dynamics/ball_environment.h"
#include "hapsim/dynamics/parallel_gripper.h"
#include "hapsim/dynamics/rigid_ball.h"
#include "hapsim/kinematics/master_arm.h"
#include "hapsim/kinematics/slave_follower.h"

#include <array>
#include <memory>

namespace hapsim {

struct TeleopWorldDescription {
  MasterArmGeometry master;
  /// The slave arm (procedural Motoman or the GP7 URDF) and its start joints (dof() values;
  /// empty: all zero, clamped into the limits).
  std::shared_ptr<const SerialChain> slave;
  std::vector<double> slave_start_rad;
  TeleopMapping mapping;
  SlaveFollowerOptions follower;
  ParallelGripperParams gripper;
  RigidBallParams ball;
  Vec3 ball_start_world = Vec3(0.55, -0.25, 0.03);
  VirtualSheetOptions sheet;
  BallEnvironmentOptions environment;
  /// How the contact force at the slave's tool is scaled back onto the master's hand.
  double force_scale = 1.0;
};

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
};

class TeleopWorld {
 public:
  /// Throws hapsim::Error naming the part that is wrong (no slave, bad geometry, ...).
  explicit TeleopWorld(TeleopWorldDescription description);

  /// One cycle. An unhealthy or non-finite master input holds the slave and commands zero
  /// torque. haptic path
  const TeleopStepResult& step(const DeviceInput& master, double dt_s) noexcept;

  [[nodiscard]] const TeleopWorldDescription& description() const { return description_; }
  [[nodiscard]] const MasterArm& master() const { return master_; }
  [[nodiscard]] const SlaveFollower& slave() const { return *slave_; }
  [[nodiscard]] const RigidBall& ball() const { return ball_; }
  [[nodiscard]] const VirtualSheet& sheet() const { return *sheet_; }
  [[nodiscard]] const ParallelGripper& gripper() const { return gripper_; }
  /// What the last step() returned (default values before the first step).
  [[nodiscard]] const TeleopStepResult& last_result() const { return result_; }

  /// The slave gripper opening for a master grip opening: the master's range mapped linearly
  /// onto the slave's.
  [[nodiscard]] double slave_width_for(double master_opening_m) const noexcept;

 private:
  TeleopWorldDescription description_;
  MasterArm master_;
  std::unique_ptr<SlaveFollower> slave_;
  ParallelGripper gripper_;
  RigidBall ball_;
  std::unique_ptr<VirtualSheet> sheet_;
  std::unique_ptr<BallEnvironment> environment_;
  TeleopStepResult result_;
  double time_s_ = 0.0;
};

}  // namespace hapsim
