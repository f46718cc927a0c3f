// The slave side of teleoperation: each cycle the master's hand pose, scaled and offset, is the
// slave tip's target; IK starts from the slave's current joints (one cycle's motion is small, so
// it converges in a few iterations), and the joints move to the answer within their speed and
// acceleration limits. A target that moves smoothly is reached every cycle, exactly as without
// the limits. A target that jumps (a served master after a stalled cycle, a far start) is caught
// up time-optimally, each joint accelerating and braking at its limit, so the slave's own motion
// stays smooth: a real arm cannot step its speed, and the kinematic pads holding a ball turned
// every such step into a force spike of up to the gripper's 20 N. While catching up the joints
// each take their own time, so the tip may leave the straight line by about the lag. The gripper
// opening follows the master's fingers within its own speed limit.
#pragma once

#include "hapsim/kinematics/inverse_kinematics.h"
#include "hapsim/kinematics/serial_chain.h"

#include <array>
#include <span>

namespace hapsim {

struct TeleopMapping {
  /// Slave motion per unit of master motion.
  double scale = 1.6;
  /// The master's (scaled) base frame in the slave's base frame.
  Iso3 X_slave_master = Iso3::Identity();
  /// Slave tool orientation (base frame) when the master's base angle is 0; the master's base
  /// rotation turns it about the slave's z. Default: the tool's z pointing down.
  Mat3 R_tool = (Mat3() << 1, 0, 0, 0, -1, 0, 0, 0, -1).finished();
};

/// The slave tip's target for a master hand position (master base frame) and base angle.
[[nodiscard]] Iso3 slave_target(const TeleopMapping& mapping, const Vec3& p_master_hand,
                                double master_base_rad) noexcept;

struct SlaveFollowerOptions {
  IkOptions ik = real_time_ik();
  /// Every joint's acceleration limit, rad/s² (m/s² for a prismatic joint); URDF has none. 30
  /// rad/s² is an industrial arm's order (its top speed, 6.5 rad/s here, in about 0.2 s) and 4×
  /// the most the scripted pick-and-place asks of the procedural Motoman (7.7 rad/s²).
  double max_joint_acceleration_per_s2 = 30.0;
  /// Parallel gripper: fully open width and opening/closing speed.
  double gripper_max_width_m = 0.10;
  double gripper_speed_m_per_s = 0.25;

  /// Tracking from last cycle's joints: no restarts, a few iterations, and on target to a
  /// micrometre: with the solver's 0.1 mm the tip stayed put until the target had moved 0.1 mm
  /// and then jumped, a 0.1 m/s spike in a carried tool's velocity every few cycles (2 N through
  /// the FEM knee's contact damping). From the last cycle's joints one or two iterations reach it.
  static IkOptions real_time_ik() {
    IkOptions o;
    o.restarts = 0;
    o.max_iterations = 20;
    o.position_tolerance_m = 1e-6;
    o.rotation_tolerance_rad = 1e-5;
    return o;
  }
};

struct SlaveStep {
  /// IK reached the target this cycle (the joints may still be catching up, see below).
  bool ik_reached = false;
  /// A joint was held to its speed limit this cycle.
  bool velocity_limited = false;
  /// A joint was held to its acceleration limit, or braked by it, this cycle: the slave is
  /// catching up with a target that moved faster than it can follow.
  bool acceleration_limited = false;
  /// Tip error after the move, metres and radians.
  double position_error_m = 0.0;
  double rotation_error_rad = 0.0;
};

class SlaveFollower {
 public:
  /// `q_start`: dof() joint values (clamped into the limits), at rest; the gripper starts open.
  /// Throws hapsim::Error on a chain with a joint lacking a finite speed limit, or on bad gripper
  /// or acceleration settings.
  SlaveFollower(const SerialChain& chain, std::span<const double> q_start,
                SlaveFollowerOptions options = {});

  /// Back to `q_start` (dof() values, clamped into the limits) at rest with the gripper open, as
  /// the constructor leaves it. haptic path (no allocation)
  void reset(std::span<const double> q_start) noexcept;

  /// One cycle towards `target` and `gripper_width_target_m`. A non-finite target is taken as
  /// stop(); a non-finite width leaves the gripper as it is. haptic path (no allocation)
  SlaveStep step(const Iso3& target, double gripper_width_target_m, double dt_s) noexcept;

  /// One cycle with no target (the master is gone): each joint brakes to rest at its
  /// acceleration limit, then stands; the gripper holds. haptic path (no allocation)
  SlaveStep stop(double dt_s) noexcept;

  [[nodiscard]] std::span<const double> q() const {
    return {q_.data(), static_cast<std::size_t>(chain_->dof())};
  }
  [[nodiscard]] Iso3 tip_pose() const noexcept { return chain_->forward(q()); }
  /// The joints' speeds over the last step, rad/s (m/s); zeros after a reset.
  [[nodiscard]] std::span<const double> velocity() const {
    return {v_.data(), static_cast<std::size_t>(chain_->dof())};
  }
  [[nodiscard]] double gripper_width_m() const { return gripper_width_m_; }
  [[nodiscard]] const SerialChain& chain() const { return *chain_; }

 private:
  /// The joints' move towards goal_ within their limits; dt > 0.
  void move_towards_goal(double dt, SlaveStep* out) noexcept;
  /// One cycle of braking towards rest; dt ≥ 0.
  void brake(double dt, SlaveStep* out) noexcept;

  const SerialChain* chain_;
  SlaveFollowerOptions options_;
  std::array<double, kMaxChainJoints> q_{};
  std::array<double, kMaxChainJoints> goal_{};
  /// Last cycle's IK answer (the goal's speed is the change), the goal's speed as the joints
  /// take it up (its change limited as theirs is), and the joints' speeds.
  std::array<double, kMaxChainJoints> previous_goal_{};
  std::array<double, kMaxChainJoints> goal_speed_{};
  std::array<double, kMaxChainJoints> v_{};
  double gripper_width_m_ = 0.0;
};

}  // namespace hapsim
