#include "hapsim/kinematics/slave_follower.h"

#include "hapsim/core/error.h"

#include <algorithm>
#include <cmath>

namespace hapsim {

Iso3 slave_target(const TeleopMapping& mapping, const Vec3& p_master_hand,
                  double master_base_rad) noexcept {
  Iso3 X = Iso3::Identity();
  X.translation() = mapping.X_slave_master * (mapping.scale * p_master_hand);
  X.linear() =
      Eigen::AngleAxisd(master_base_rad, Vec3::UnitZ()).toRotationMatrix() * mapping.R_tool;
  return X;
}

SlaveFollower::SlaveFollower(const SerialChain& chain, std::span<const double> q_start,
                             SlaveFollowerOptions options)
    : chain_(&chain), options_(options) {
  for (const ChainJoint& j : chain.joints()) {
    if (!std::isfinite(j.max_velocity)) {
      throw Error("joint '" + j.name + "'",
                  "the slave needs a finite speed limit on every joint (URDF <limit velocity>)");
    }
  }
  if (!(options_.gripper_max_width_m > 0.0) || !(options_.gripper_speed_m_per_s > 0.0) ||
      !std::isfinite(options_.gripper_max_width_m) ||
      !std::isfinite(options_.gripper_speed_m_per_s)) {
    throw Error("slave gripper", "width and speed must be finite and > 0");
  }
  reset(q_start);
}

// haptic path
void SlaveFollower::reset(std::span<const double> q_start) noexcept {
  const auto n = static_cast<std::size_t>(chain_->dof());
  q_.fill(0.0);
  goal_.fill(0.0);
  std::copy(q_start.begin(),
            q_start.begin() + static_cast<std::ptrdiff_t>(std::min(n, q_start.size())), q_.begin());
  chain_->clamp_to_limits({q_.data(), n});
  gripper_width_m_ = options_.gripper_max_width_m;  // starts open
}

SlaveStep SlaveFollower::step(const Iso3& target, double gripper_width_target_m,
                              double dt_s) noexcept {
  SlaveStep out;
  const int n = chain_->dof();
  const auto nn = static_cast<std::size_t>(n);
  const double dt = std::isfinite(dt_s) && dt_s > 0.0 ? dt_s : 0.0;
  if (target.matrix().allFinite()) {
    const IkResult r = solve_ik(*chain_, target, q(), {goal_.data(), nn}, options_.ik);
    out.ik_reached = r.reached;
    // One factor for all joints: the slowest joint sets the pace, the motion keeps its shape.
    double factor = 1.0;
    for (std::size_t i = 0; i < nn; ++i) {
      const double delta = std::abs(goal_[i] - q_[i]);
      const double allowed = chain_->joints()[i].max_velocity * dt;
      if (delta > allowed) {
        factor = std::min(factor, allowed / delta);
      }
    }
    out.velocity_limited = factor < 1.0;
    for (std::size_t i = 0; i < nn; ++i) {
      q_[i] += factor * (goal_[i] - q_[i]);
    }
    chain_->clamp_to_limits({q_.data(), nn});
    pose_error(chain_->forward(q()), target, &out.position_error_m, &out.rotation_error_rad);
  }
  if (std::isfinite(gripper_width_target_m)) {
    const double goal = std::clamp(gripper_width_target_m, 0.0, options_.gripper_max_width_m);
    const double step = options_.gripper_speed_m_per_s * dt;
    gripper_width_m_ += std::clamp(goal - gripper_width_m_, -step, step);
  }
  return out;
}

}  // namespace hapsim
