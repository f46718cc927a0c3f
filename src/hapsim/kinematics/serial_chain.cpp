#include "hapsim/kinematics/serial_chain.h"

#include "hapsim/core/error.h"

#include <algorithm>
#include <array>
#include <cmath>

namespace hapsim {

namespace {

bool finite_iso(const Iso3& X) {
  return X.matrix().allFinite();
}

}  // namespace

Iso3 joint_motion(const ChainJoint& joint, double q) noexcept {
  Iso3 M = Iso3::Identity();
  if (joint.type == JointType::kRevolute) {
    M.linear() = Eigen::AngleAxisd(q, joint.axis).toRotationMatrix();
  } else {
    M.translation() = q * joint.axis;
  }
  return M;
}

SerialChain::SerialChain(std::string base_link, std::vector<ChainJoint> joints, Iso3 X_last_tip,
                         std::string tip_link)
    : base_link_(std::move(base_link)),
      joints_(std::move(joints)),
      X_last_tip_(std::move(X_last_tip)),
      tip_link_(std::move(tip_link)) {
  if (joints_.size() > static_cast<std::size_t>(kMaxChainJoints)) {
    throw Error("chain " + base_link_ + " -> " + tip_link_,
                std::to_string(joints_.size()) + " movable joints; at most " +
                    std::to_string(kMaxChainJoints) + " are supported");
  }
  for (ChainJoint& j : joints_) {
    const std::string where = "joint '" + j.name + "'";
    if (!finite_iso(j.X_parent_joint)) {
      throw Error(where, "origin is not a finite transform");
    }
    const double len = j.axis.norm();
    if (!std::isfinite(len) || len < 1e-12) {
      throw Error(where, "axis is zero or not finite; expected a direction");
    }
    j.axis /= len;
    if (std::isnan(j.lower) || std::isnan(j.upper) || j.lower > j.upper) {
      throw Error(where, "limits [" + std::to_string(j.lower) + ", " + std::to_string(j.upper) +
                             "]: expected lower <= upper");
    }
    if (std::isnan(j.max_velocity) || j.max_velocity <= 0.0) {
      throw Error(where, "velocity limit " + std::to_string(j.max_velocity) + ": expected > 0");
    }
  }
  if (!finite_iso(X_last_tip_)) {
    throw Error("chain tip '" + tip_link_ + "'", "tip transform is not finite");
  }
}

Iso3 SerialChain::forward(std::span<const double> q) const noexcept {
  Iso3 X = Iso3::Identity();
  for (std::size_t i = 0; i < joints_.size(); ++i) {
    X = X * joints_[i].X_parent_joint * joint_motion(joints_[i], q[i]);
  }
  return X * X_last_tip_;
}

Iso3 SerialChain::frames(std::span<const double> q, std::span<Iso3> frames) const noexcept {
  Iso3 X = Iso3::Identity();
  for (std::size_t i = 0; i < joints_.size(); ++i) {
    X = X * joints_[i].X_parent_joint * joint_motion(joints_[i], q[i]);
    frames[i] = X;
  }
  return X * X_last_tip_;
}

ChainJacobian SerialChain::jacobian(std::span<const double> q) const noexcept {
  ChainJacobian J(6, dof());
  std::array<Iso3, kMaxChainJoints> F;
  const Iso3 tip = frames(q, F);
  const Vec3 p_tip = tip.translation();
  for (int i = 0; i < dof(); ++i) {
    const ChainJoint& j = joints_[static_cast<std::size_t>(i)];
    // The axis is fixed in the joint frame, which its own motion does not turn.
    const Vec3 a = F[static_cast<std::size_t>(i)].linear() * j.axis;
    if (j.type == JointType::kRevolute) {
      J.block<3, 1>(0, i) = a.cross(p_tip - F[static_cast<std::size_t>(i)].translation());
      J.block<3, 1>(3, i) = a;
    } else {
      J.block<3, 1>(0, i) = a;
      J.block<3, 1>(3, i).setZero();
    }
  }
  return J;
}

bool SerialChain::within_limits(std::span<const double> q) const noexcept {
  for (std::size_t i = 0; i < joints_.size(); ++i) {
    if (!(q[i] >= joints_[i].lower && q[i] <= joints_[i].upper) || !std::isfinite(q[i])) {
      return false;
    }
  }
  return true;
}

void SerialChain::clamp_to_limits(std::span<double> q) const noexcept {
  for (std::size_t i = 0; i < joints_.size(); ++i) {
    const ChainJoint& j = joints_[i];
    if (std::isnan(q[i])) {
      q[i] = std::isfinite(j.lower) && std::isfinite(j.upper) ? 0.5 * (j.lower + j.upper)
                                                              : std::clamp(0.0, j.lower, j.upper);
    }
    q[i] = std::clamp(q[i], j.lower, j.upper);
  }
}

void SerialChain::set_link_geometry(std::vector<ChainLinkGeometry> links) {
  for (const ChainLinkGeometry& l : links) {
    if (l.frame < -1 || l.frame >= dof()) {
      throw Error("link '" + l.link + "'",
                  "frame index " + std::to_string(l.frame) + " is not in the chain");
    }
  }
  links_ = std::move(links);
}

int SerialChain::frame_of_link(const std::string& link) const {
  if (link == base_link_) {
    return -1;
  }
  for (std::size_t i = 0; i < joints_.size(); ++i) {
    if (joints_[i].child_link == link) {
      return static_cast<int>(i);
    }
  }
  return -2;
}

}  // namespace hapsim
