#include "hapsim/script/master_flange_ik.h"

#include "hapsim/core/error.h"
#include "hapsim/kinematics/inverse_kinematics.h"

#include <cmath>
#include <utility>

namespace hapsim {

MasterFlangeIk::MasterFlangeIk(const MasterArm& master, const TeleopMapping& mapping,
                               double slave_max_width_m, std::string where)
    : master_(&master),
      mapping_(mapping),
      slave_max_width_m_(slave_max_width_m),
      where_(std::move(where)) {
  if (!(slave_max_width_m > 0.0) || !(mapping.scale > 0.0)) {
    throw Error(where_, "the gripper width and the mapping scale must be > 0");
  }
}

DeviceInput MasterFlangeIk::input_for(double time_s, const Vec3& flange_world, double width_m) {
  const Vec3 hand = mapping_.X_slave_master.inverse() * flange_world / mapping_.scale;
  Iso3 target = Iso3::Identity();
  target.translation() = hand;
  IkOptions ik;
  ik.orientation = false;
  ik.restarts = 8;
  // To a micrometre, not the solver's 0.1 mm: tracked from the last solution, a path that moves
  // less than the tolerance per sample leaves the joints where they were, and a 0.05 m/s press
  // moved the master in 0.2 mm steps every 3-4 ms: velocity spikes of 0.2 m/s, which a device
  // host renders through the contact's damping.
  ik.position_tolerance_m = 1e-6;
  std::array<double, 3> solved{};
  const IkResult r = solve_ik(master_->arm(), target, q_, solved, ik);
  if (!r.reached) {
    throw Error(where_, "the slave flange target (" + std::to_string(flange_world.x()) + ", " +
                            std::to_string(flange_world.y()) + ", " +
                            std::to_string(flange_world.z()) +
                            ") m maps to a master hand position out of the master's reach");
  }
  q_ = solved;
  const MasterArmGeometry& g = master_->geometry();
  const double widest = 2.0 * g.finger_m * std::sin(g.finger_open_limit_rad);
  const double finger =
      master_->finger_angle_for_opening(g.finger_gap_m + width_m / slave_max_width_m_ * widest);
  DeviceInput in;
  in.time_s = time_s;
  in.p_world = hand;
  in.joint_count = 3;
  in.joint_rad[0] = q_[0];
  in.joint_rad[1] = q_[1];
  in.joint_rad[2] = q_[2];
  in.finger_count = 2;
  in.finger_rad[0] = finger;
  in.finger_rad[1] = finger;
  return in;
}

}  // namespace hapsim
