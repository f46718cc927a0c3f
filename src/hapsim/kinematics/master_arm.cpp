#include "hapsim/kinematics/master_arm.h"

#include "hapsim/core/error.h"

#include <algorithm>
#include <cmath>
#include <string>

namespace hapsim {

namespace {

SerialChain make_arm(const MasterArmGeometry& g) {
  std::vector<ChainJoint> joints(3);
  joints[0].name = "master_base";
  joints[0].axis = Vec3::UnitZ();
  joints[0].child_link = "master_turret";
  joints[1].name = "master_shoulder";
  joints[1].X_parent_joint = Iso3(Eigen::Translation3d(0.0, 0.0, g.shoulder_height_m));
  joints[1].axis = Vec3::UnitY();
  joints[1].child_link = "master_upper_arm";
  joints[2].name = "master_elbow";
  // The upper arm points up at shoulder 0; the forearm points forward (+x) at elbow π/2.
  joints[2].X_parent_joint = Iso3(Eigen::Translation3d(0.0, 0.0, g.upper_arm_m));
  joints[2].axis = Vec3::UnitY();
  joints[2].child_link = "master_forearm";
  for (std::size_t i = 0; i < 3; ++i) {
    joints[i].lower = g.lower_rad[i];
    joints[i].upper = g.upper_rad[i];
  }
  return SerialChain("master_base", std::move(joints),
                     Iso3(Eigen::Translation3d(0.0, 0.0, g.forearm_m)), "master_hand");
}

const MasterArmGeometry& checked(const MasterArmGeometry& g) {
  for (const double l : {g.shoulder_height_m, g.upper_arm_m, g.forearm_m, g.finger_m}) {
    if (!std::isfinite(l) || l <= 0.0) {
      throw Error("master arm", "lengths must be > 0 m, got " + std::to_string(l));
    }
  }
  if (!std::isfinite(g.finger_gap_m) || g.finger_gap_m < 0.0 ||
      !std::isfinite(g.finger_open_limit_rad) || g.finger_open_limit_rad <= 0.0) {
    throw Error("master arm", "finger gap must be >= 0 m and the opening limit > 0 rad");
  }
  for (std::size_t i = 0; i < 3; ++i) {
    if (!(g.max_torque_n_m[i] >= 0.0)) {
      throw Error("master arm", "motor torque limits must be >= 0 N*m");
    }
  }
  if (!(g.max_finger_torque_n_m >= 0.0)) {
    throw Error("master arm", "finger motor torque limit must be >= 0 N*m");
  }
  return g;
}

}  // namespace

MasterArm::MasterArm(MasterArmGeometry geometry)
    : geometry_(checked(geometry)), arm_(make_arm(geometry_)) {}

Iso3 MasterArm::hand_pose(const std::array<double, 3>& arm_rad) const noexcept {
  return arm_.forward(arm_rad);
}

double MasterArm::grip_opening_m(const std::array<double, 2>& finger_rad) const noexcept {
  double opening = geometry_.finger_gap_m;
  for (double a : finger_rad) {
    a = std::isfinite(a) ? std::clamp(a, 0.0, geometry_.finger_open_limit_rad) : 0.0;
    opening += geometry_.finger_m * std::sin(a);  // each pad swings out by L·sin(a)
  }
  return opening;
}

double MasterArm::finger_angle_for_opening(double opening_m) const noexcept {
  if (!std::isfinite(opening_m)) {
    return 0.0;
  }
  const double s = (opening_m - geometry_.finger_gap_m) / (2.0 * geometry_.finger_m);
  return std::clamp(std::asin(std::clamp(s, 0.0, 1.0)), 0.0, geometry_.finger_open_limit_rad);
}

MasterTorques MasterArm::torques(const std::array<double, 3>& arm_rad, const Vec3& force_base_n,
                                 double grasp_force_n) const noexcept {
  MasterTorques t;
  bool finite = force_base_n.allFinite() && std::isfinite(grasp_force_n);
  for (const double q : arm_rad) {
    finite = finite && std::isfinite(q);
  }
  if (!finite) {
    return t;  // never push on a guess
  }
  const ChainJacobian J = arm_.jacobian(arm_rad);
  const Eigen::Vector3d tau = J.topRows<3>().transpose() * force_base_n;
  for (std::size_t i = 0; i < 3; ++i) {
    const double limit = geometry_.max_torque_n_m[i];
    t.arm_n_m[i] = std::clamp(tau[static_cast<Eigen::Index>(i)], -limit, limit);
    t.clamped = t.clamped || t.arm_n_m[i] != tau[static_cast<Eigen::Index>(i)];
  }
  // The grasp force pushes each finger open (against the operator's squeeze).
  const double finger = std::max(grasp_force_n, 0.0) * geometry_.finger_m;
  for (double& f : t.fingers_n_m) {
    f = std::min(finger, geometry_.max_finger_torque_n_m);
    t.clamped = t.clamped || f != finger;
  }
  return t;
}

}  // namespace hapsim
