// The master input that puts a teleoperation slave's flange at a point (000 §4): the flange →
// the master's hand through the inverse of the teleop mapping → the master's arm joints by
// position IK (tracked from the previous call, so a smooth path gives smooth joints), and the
// master's fingers opened to give a slave gripper opening. Scripts for the master are written
// as slave flange positions this way (pick_and_place_trajectory.h, teleop_probe_plan.h), so one
// script works whatever the scale, offset or master geometry.
#pragma once

#include "hapsim/core/device_io.h"
#include "hapsim/core/types.h"
#include "hapsim/kinematics/master_arm.h"
#include "hapsim/kinematics/slave_follower.h"

#include <array>
#include <string>

namespace hapsim {

class MasterFlangeIk {
 public:
  /// `where` names the script in errors. Throws hapsim::Error (`where`) when the gripper width or
  /// the mapping's scale is not > 0.
  MasterFlangeIk(const MasterArm& master, const TeleopMapping& mapping, double slave_max_width_m,
                 std::string where);

  /// The master's input at `time_s` for the slave's flange at `flange_world` with its gripper
  /// `width_m` open: joint_rad[0..2] arm, finger_rad[0..1] fingers, p_world the master's hand.
  /// Throws hapsim::Error (`where`) naming the flange target when the master cannot reach it.
  [[nodiscard]] DeviceInput input_for(double time_s, const Vec3& flange_world, double width_m);

 private:
  const MasterArm* master_;
  TeleopMapping mapping_;
  double slave_max_width_m_;
  std::string where_;
  std::array<double, 3> q_{0.0, 0.8, 1.4};  // the last solution: the next solve starts there
};

}  // namespace hapsim
