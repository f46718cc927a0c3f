// Serial chains from a Denavit–Hartenberg table (standard convention): link i's transform is
// Rz(θ_i + q_i)·Tz(d_i)·Tx(a_i)·Rx(α_i) for a revolute joint, Rz(θ_i)·Tz(d_i + q_i)·Tx(a_i)·Rx(α_i)
// for a prismatic one. The master arm of the teleoperation paper is given this way.
#pragma once

#include "hapsim/kinematics/serial_chain.h"

#include <span>
#include <string>

namespace hapsim {

struct DhRow {
  double a_m = 0.0;
  double alpha_rad = 0.0;
  double d_m = 0.0;
  /// Constant offset added to the joint angle (revolute) or the angle itself (prismatic).
  double theta_rad = 0.0;
  JointType type = JointType::kRevolute;
  double lower = -kInf;
  double upper = kInf;
  double max_velocity = kInf;
  std::string name = {};  // empty: "joint_<i>"
};

/// One movable joint per row; links are named "link_0" (base) .. "link_<n>" (tip).
[[nodiscard]] SerialChain make_dh_chain(std::span<const DhRow> rows);

}  // namespace hapsim
