#include "hapsim/dynamics/parallel_gripper.h"

#include "hapsim/core/error.h"

#include <algorithm>
#include <cmath>
#include <utility>

namespace hapsim {

namespace {

constexpr std::array<double, 2> kSide{1.0, -1.0};

}  // namespace

ParallelGripper::ParallelGripper(ParallelGripperParams params) : params_(std::move(params)) {
  if (!(params_.pad_half_m.minCoeff() > 0.0) || !params_.pad_half_m.allFinite() ||
      !std::isfinite(params_.pad_depth_m)) {
    throw Error("gripper", "pad sizes must be finite and > 0 m");
  }
  if (!(params_.pad_contact.stiffness_n_per_m > 0.0) || !(params_.max_force_n > 0.0) ||
      !std::isfinite(params_.max_force_n) || !(params_.safety_factor >= 1.0)) {
    throw Error("gripper", "pad stiffness and force limit must be > 0, the safety factor >= 1");
  }
}

Vec3 ParallelGripper::pad_center_world(const Iso3& X_world_tool, double width_m, int pad) const {
  const double y = kSide[static_cast<std::size_t>(pad)] * (0.5 * width_m + params_.pad_half_m.y());
  return X_world_tool * Vec3(0.0, y, params_.pad_depth_m);
}

GripperReport ParallelGripper::step(const Iso3& X_world_tool, double commanded_width_m,
                                    RigidBall& ball, double dt_s) noexcept {
  GripperReport out;
  if (!X_world_tool.matrix().allFinite() || !std::isfinite(commanded_width_m)) {
    out.held = held_;
    return out;  // no new information: leave everything as it was
  }
  const double r = ball.params().radius_m;
  const Iso3 X_tool_world = X_world_tool.inverse();
  const Vec3 c = held_ ? p_tool_ball_ : Vec3(X_tool_world * ball.p_world());
  const Vec3& half = params_.pad_half_m;

  // The pads close symmetrically until the first one presses the ball at the force limit.
  double width = std::max(commanded_width_m, 0.0);
  // Squeezed only when the ball's centre lies between the pad faces (not under or beside them).
  const bool between =
      std::abs(c.x()) <= half.x() && std::abs(c.z() - params_.pad_depth_m) <= half.z();
  if (between) {
    const double pen_max = params_.max_force_n / params_.pad_contact.stiffness_n_per_m;
    width = std::max(width, 2.0 * (r - pen_max + std::abs(c.y())));
  }
  out.width_m = width;

  const Mat3 R = X_world_tool.linear();
  const Vec3 c_world = X_world_tool * c;
  std::array<Vec3, 2> normals{Vec3::Zero(), Vec3::Zero()};
  Vec3 total = Vec3::Zero();
  for (int i = 0; i < 2; ++i) {
    const auto si = static_cast<std::size_t>(i);
    const Vec3 center(0.0, kSide[si] * (0.5 * width + half.y()), params_.pad_depth_m);
    const Vec3 q = center + (c - center).cwiseMax(-half).cwiseMin(half);
    const Vec3 d = c - q;
    const double dist = d.norm();
    // A centre inside a pad (a violent squeeze) is pushed towards the other pad.
    const Vec3 n_tool = dist > 1e-12 ? Vec3(d / dist) : Vec3(0.0, -kSide[si], 0.0);
    const double pen = dist > 1e-12 ? r - dist : r;
    const Vec3 pad_world = X_world_tool * center;
    const Vec3 v_pad = has_previous_ && dt_s > 0.0
                           ? Vec3((pad_world - previous_pad_world_[si]) / dt_s)
                           : Vec3::Zero();
    previous_pad_world_[si] = pad_world;
    const Vec3 n_world = R * n_tool;
    const Vec3 v_ball = held_ ? v_pad : ball.v_world();
    const Vec3 f = contact_spring_force(params_.pad_contact, pen, n_world, v_ball - v_pad, c_world,
                                        anchors_[si]);
    // The squeeze is the spring's share (damping only while the pads move): what the grasp and
    // the master's fingers go by.
    out.pad_force_n[si] = f.squaredNorm() > 0.0
                              ? std::min(params_.pad_contact.stiffness_n_per_m * std::max(pen, 0.0),
                                         params_.max_force_n * (1.0 + 1e-9))
                              : 0.0;
    normals[si] = n_world;
    total += f;
  }
  has_previous_ = true;

  const double weight = ball.params().mass_kg * ball.params().gravity_m_per_s2.norm();
  const bool both =
      out.pad_force_n[0] > 0.0 && out.pad_force_n[1] > 0.0 && normals[0].dot(normals[1]) < -0.5;
  const double friction = params_.pad_contact.friction;
  if (!held_ && both &&
      friction * (out.pad_force_n[0] + out.pad_force_n[1]) >= params_.safety_factor * weight) {
    held_ = true;
    out.grasped_now = true;
    p_tool_ball_ = c;
  } else if (held_ && !both) {
    held_ = false;
    out.released_now = true;
    ball.release();
  }
  if (held_) {
    ball.hold(X_world_tool, p_tool_ball_, dt_s);
  } else {
    out.force_on_ball_world_n = total;
  }
  out.held = held_;
  return out;
}

}  // namespace hapsim
