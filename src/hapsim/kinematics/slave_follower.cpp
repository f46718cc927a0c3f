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
  if (!(options_.max_joint_acceleration_per_s2 > 0.0) ||
      !std::isfinite(options_.max_joint_acceleration_per_s2)) {
    throw Error("slave joints", "the acceleration limit must be finite and > 0");
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
  previous_goal_ = q_;  // at rest on its goal
  goal_speed_.fill(0.0);
  v_.fill(0.0);
  gripper_width_m_ = options_.gripper_max_width_m;  // starts open
}

namespace {

// The fastest a joint may close on a goal `distance` away (≥ 0) and still stop on it, braking by
// `dv` = acceleration × dt each step: from n·dv it covers dt·dv·n(n+1)/2 before it stands.
double braking_speed(double distance, double dv, double dt) {
  const double n = std::sqrt(0.25 + 2.0 * distance / (dv * dt)) - 0.5;
  return std::min(distance / dt, n * dv);
}

}  // namespace

// haptic path
void SlaveFollower::move_towards_goal(double dt, SlaveStep* out) noexcept {
  const auto nn = static_cast<std::size_t>(chain_->dof());
  const double dv = options_.max_joint_acceleration_per_s2 * dt;
  // Each joint relative to its goal, which moves at u (last cycle's IK answer to this one's): the
  // joint closes the lag r it would have on the goal moving at u no faster than it can brake to
  // a stop on it, and changes its speed by at most dv. A goal moving smoothly leaves no lag
  // (|r| ≤ dv·dt: the joint lands on the goal), so the limits never act on a smooth motion.
  std::array<double, kMaxChainJoints> v_new{};
  bool lands = true;
  for (std::size_t i = 0; i < nn; ++i) {
    const double land = (goal_[i] - q_[i]) / dt;
    // The goal's speed as the joint may take it up: a goal that jumped (several of the master's
    // cycles at once) is lag to close, not a speed to match in one step.
    const double u =
        std::clamp((goal_[i] - previous_goal_[i]) / dt, goal_speed_[i] - dv, goal_speed_[i] + dv);
    goal_speed_[i] = u;
    const double r = goal_[i] - q_[i] - u * dt;
    const double wanted = u + std::copysign(braking_speed(std::abs(r), dv, dt), r);
    const double max_velocity = chain_->joints()[i].max_velocity;
    const double by_acceleration = std::clamp(wanted, v_[i] - dv, v_[i] + dv);
    v_new[i] = std::clamp(by_acceleration, -max_velocity, max_velocity);
    out->acceleration_limited |= by_acceleration != wanted || std::abs(r) > dv * dt;
    out->velocity_limited |= v_new[i] != by_acceleration;
    lands = lands && std::abs(r) <= dv * dt && std::abs(land - v_[i]) <= dv &&
            std::abs(land) <= max_velocity;
  }
  const std::array<double, kMaxChainJoints> q_before = q_;
  for (std::size_t i = 0; i < nn; ++i) {
    // Landing is the unlimited follower's own step, to the bit: a smooth run is unchanged.
    q_[i] += lands ? goal_[i] - q_[i] : v_new[i] * dt;
  }
  chain_->clamp_to_limits({q_.data(), nn});
  for (std::size_t i = 0; i < nn; ++i) {
    v_[i] = (q_[i] - q_before[i]) / dt;
  }
  if (lands) {
    out->acceleration_limited = out->velocity_limited = false;
  }
  previous_goal_ = goal_;
}

// haptic path
void SlaveFollower::brake(double dt, SlaveStep* out) noexcept {
  const auto nn = static_cast<std::size_t>(chain_->dof());
  const double dv = options_.max_joint_acceleration_per_s2 * dt;
  const std::array<double, kMaxChainJoints> q_before = q_;
  for (std::size_t i = 0; i < nn; ++i) {
    out->acceleration_limited |= std::abs(v_[i]) > dv;
    v_[i] -= std::clamp(v_[i], -dv, dv);
    q_[i] += v_[i] * dt;
  }
  chain_->clamp_to_limits({q_.data(), nn});
  for (std::size_t i = 0; i < nn; ++i) {
    v_[i] = dt > 0.0 ? (q_[i] - q_before[i]) / dt : v_[i];
  }
  previous_goal_ = q_;  // a new target is taken up from rest here
  goal_speed_.fill(0.0);
}

SlaveStep SlaveFollower::stop(double dt_s) noexcept {
  SlaveStep out;
  brake(std::isfinite(dt_s) && dt_s > 0.0 ? dt_s : 0.0, &out);
  return out;
}

SlaveStep SlaveFollower::step(const Iso3& target, double gripper_width_target_m,
                              double dt_s) noexcept {
  SlaveStep out;
  const int n = chain_->dof();
  const auto nn = static_cast<std::size_t>(n);
  const double dt = std::isfinite(dt_s) && dt_s > 0.0 ? dt_s : 0.0;
  if (!target.matrix().allFinite()) {
    brake(dt, &out);
  } else {
    const IkResult r = solve_ik(*chain_, target, q(), {goal_.data(), nn}, options_.ik);
    out.ik_reached = r.reached;
    if (dt > 0.0) {
      move_towards_goal(dt, &out);
    }
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
