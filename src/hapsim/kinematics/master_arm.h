// The 5-DOF master arm of the teleoperation paper (000 §1): the arm turns about Z at its base and
// about Y at the shoulder and the elbow (3 DOF place the hand), and two finger joints close
// against each other to grasp. The world frame is the arm's base. Forces come back the other way:
// a contact force at the hand becomes joint torques τ = Jᵀ·F (clamped per joint to what its motor
// gives), a grasp force becomes a torque on each finger joint.
#pragma once

#include "hapsim/kinematics/serial_chain.h"

#include <array>

namespace hapsim {

struct MasterArmGeometry {
  /// Shoulder height above the base, upper arm and forearm lengths, metres.
  double shoulder_height_m = 0.20;
  double upper_arm_m = 0.25;
  double forearm_m = 0.25;
  /// Finger length (pivot to the pad that touches the other finger), metres; pivots sit
  /// ± finger_gap_m / 2 apart at the hand.
  double finger_m = 0.06;
  double finger_gap_m = 0.02;
  /// Joint limits, radians: base, shoulder, elbow; each finger opens from 0 (closed) up.
  std::array<double, 3> lower_rad{-2.6, -0.3, 0.2};
  std::array<double, 3> upper_rad{2.6, 1.6, 2.6};
  double finger_open_limit_rad = 0.8;
  /// Largest motor torque per arm joint (N·m) and per finger joint.
  std::array<double, 3> max_torque_n_m{4.0, 4.0, 2.5};
  double max_finger_torque_n_m = 0.4;
};

struct MasterTorques {
  std::array<double, 3> arm_n_m{};
  std::array<double, 2> fingers_n_m{};
  /// Whether any torque had to be clamped to its motor's limit.
  bool clamped = false;
};

class MasterArm {
 public:
  /// Throws hapsim::Error on non-positive lengths or inverted limits.
  explicit MasterArm(MasterArmGeometry geometry = {});

  [[nodiscard]] const MasterArmGeometry& geometry() const { return geometry_; }
  /// The 3-joint arm (base Z, shoulder Y, elbow Y) from the base to the hand.
  [[nodiscard]] const SerialChain& arm() const { return arm_; }

  /// Hand pose in the base frame for the arm joints. haptic path
  [[nodiscard]] Iso3 hand_pose(const std::array<double, 3>& arm_rad) const noexcept;
  /// Distance between the finger pads for the two finger angles (each clamped to [0, limit]).
  [[nodiscard]] double grip_opening_m(const std::array<double, 2>& finger_rad) const noexcept;
  /// Finger angle that gives `opening_m` (both fingers alike), clamped to the range.
  [[nodiscard]] double finger_angle_for_opening(double opening_m) const noexcept;

  /// Joint torques rendering `force_base_n` at the hand (τ = Jᵀ·F) and `grasp_force_n` squeezing
  /// the fingers open (each finger gets grasp force × finger length), clamped per motor; a
  /// non-finite input gives zero torque. haptic path
  [[nodiscard]] MasterTorques torques(const std::array<double, 3>& arm_rad,
                                      const Vec3& force_base_n,
                                      double grasp_force_n) const noexcept;

 private:
  MasterArmGeometry geometry_;
  SerialChain arm_;
};

}  // namespace hapsim
