#include "hapsim/device/master_probe_device.h"

#include <cmath>

namespace hapsim {

MasterHandMapping::MasterHandMapping(MasterArm master, const std::array<double, 3>& seed_rad)
    : master_(std::move(master)), arm_rad_(seed_rad) {
  // Position only (the master's 3 joints place the hand), tracked from the last answer: a probe
  // moves a few millimetres per frame, so the seed converges in a few iterations; the restarts
  // only matter after a jump, and bound the worst case (out of reach) to 3 × 40 iterations.
  ik_.orientation = false;
  ik_.restarts = 2;
  ik_.max_iterations = 40;
  const MasterArmGeometry& g = master_.geometry();
  const double widest = 2.0 * g.finger_m * std::sin(g.finger_open_limit_rad);
  open_finger_rad_ = master_.finger_angle_for_opening(g.finger_gap_m + widest);
}

void MasterHandMapping::set_probe_in_slave_frame(const TeleopMapping& mapping) {
  probe_in_slave_frame_ = true;
  scale_ = mapping.scale > 0.0 ? mapping.scale : 1.0;
  X_master_slave_ = mapping.X_slave_master.inverse();
  solved_for_ = Vec3::Constant(kInf);
}

Vec3 MasterHandMapping::probe_for(const std::array<double, 3>& arm_rad) const {
  const Vec3 hand = master_.hand_pose(arm_rad).translation();
  return probe_in_slave_frame_ ? Vec3(X_master_slave_.inverse() * (scale_ * hand)) : hand;
}

// haptic path
DeviceInput MasterHandMapping::master_input(const DeviceInput& probe) noexcept {
  if (probe.p_world.allFinite() && probe.p_world != solved_for_) {
    Iso3 target = Iso3::Identity();
    target.translation() =
        probe_in_slave_frame_ ? Vec3(X_master_slave_ * probe.p_world / scale_) : probe.p_world;
    std::array<double, 3> solved{};
    const IkResult r = solve_ik(master_.arm(), target, arm_rad_, solved, ik_);
    // Not reached: solve_ik leaves its best pose (the arm stretched towards the probe).
    if (std::isfinite(solved[0]) && std::isfinite(solved[1]) && std::isfinite(solved[2])) {
      arm_rad_ = solved;
    }
    reached_ = r.reached;
    solved_for_ = probe.p_world;
  }
  DeviceInput in;
  in.time_s = probe.time_s;
  in.p_world = probe.p_world;
  in.q_world = probe.q_world;
  in.buttons = probe.buttons;
  in.healthy = probe.healthy;
  in.joint_count = 3;
  in.joint_rad[0] = arm_rad_[0];
  in.joint_rad[1] = arm_rad_[1];
  in.joint_rad[2] = arm_rad_[2];
  in.finger_count = 2;
  const double finger = (probe.buttons & 1U) != 0U ? 0.0 : open_finger_rad_;
  in.finger_rad[0] = finger;
  in.finger_rad[1] = finger;
  return in;
}

}  // namespace hapsim
