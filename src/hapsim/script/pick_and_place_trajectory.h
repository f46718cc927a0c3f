// The teleoperation scene's scripted master (000 §4): the operator's hand explores the ball, goes
// down around it, closes the fingers, lifts, carries it over the sheet, lowers it and lets go,
// then backs off. The script is written as slave flange positions (where the gripper should be)
// and turned into master joint angles through the teleop mapping and the master arm's own IK,
// so the same script works whatever the scale, offset or master geometry.
#pragma once

#include "hapsim/kinematics/master_arm.h"
#include "hapsim/kinematics/slave_follower.h"
#include "hapsim/script/trajectory.h"

#include <string>
#include <vector>

namespace hapsim {

struct PickAndPlaceScript {
  /// The ball's centre where it rests, and where it should end up resting (world, metres).
  Vec3 pick_world = Vec3(0.5, -0.25, 0.03);
  Vec3 place_world = Vec3(0.5, 0.25, 0.08);
  /// How far below the flange, along the tool's approach axis, the ball's centre is held: the
  /// gripper's pad depth, or deeper when the ball is taller than the pads so that the gripper's
  /// palm above them clears it (grasp_depth_m()).
  double grasp_depth_m = 0.07;
  /// Slave gripper openings: open (around the ball) and the closing command (pads stop on it).
  double open_width_m = 0.09;
  double closed_width_m = 0.0;
  /// Clearance above the ball while hovering, carrying and backing off; exploration circle.
  double clearance_m = 0.12;
  double explore_radius_m = 0.04;
  /// Release this high above the resting spot (the ball drops onto the sheet).
  double release_height_m = 0.002;
  /// Phase durations, seconds (> 0).
  double hover_s = 1.2, explore_s = 1.5, descend_s = 1.0, close_s = 0.6, lift_s = 0.8,
         carry_s = 2.0, lower_s = 1.0, open_s = 0.5, retreat_s = 0.8, settle_s = 1.5;
  double sample_period_s = 0.001;
};

struct PickAndPlacePhase {
  std::string name;  // "hover", "explore", "descend", "close", ...
  double start_s = 0.0;
  double end_s = 0.0;
};

struct PickAndPlacePlan {
  /// Master inputs: joint_rad[0..2] arm, finger_rad[0..1] fingers; the hand pose as p/q.
  Trajectory trajectory;
  std::vector<PickAndPlacePhase> phases;
  /// The slave flange target at the start (for starting the slave there).
  Vec3 first_flange_world = Vec3::Zero();
};

/// Where a parallel gripper holds a ball's centre below its flange: at the pads' centre depth, or
/// lower when the ball's radius is more than the pads' half height, so the palm just above the
/// pads stays `clearance_m` clear of the ball's top (a grasp centred on the pads would press the
/// palm into it).
[[nodiscard]] double grasp_depth_m(double pad_depth_m, double pad_half_height_m,
                                   double ball_radius_m, double clearance_m = 0.003);

/// Throws hapsim::Error ("pick-and-place script") when a duration is not positive or a waypoint
/// is out of the master arm's reach through the mapping.
[[nodiscard]] PickAndPlacePlan make_pick_and_place_plan(const PickAndPlaceScript& script,
                                                        const MasterArm& master,
                                                        const TeleopMapping& mapping,
                                                        double slave_max_width_m);

}  // namespace hapsim
