#include "hapsim/dynamics/rigid_ball.h"

#include "hapsim/core/error.h"

#include <cmath>
#include <string>
#include <utility>

namespace hapsim {

RigidBall::RigidBall(RigidBallParams params, const Vec3& p_world, const Vec3& v_world)
    : params_(std::move(params)), p_(p_world), v_(v_world) {
  if (!std::isfinite(params_.mass_kg) || params_.mass_kg <= 0.0) {
    throw Error("ball", "mass must be > 0 kg, got " + std::to_string(params_.mass_kg));
  }
  if (!std::isfinite(params_.radius_m) || params_.radius_m <= 0.0) {
    throw Error("ball", "radius must be > 0 m, got " + std::to_string(params_.radius_m));
  }
  if (!params_.gravity_m_per_s2.allFinite() || !p_.allFinite() || !v_.allFinite()) {
    throw Error("ball", "gravity, start position and velocity must be finite");
  }
}

void RigidBall::step(const Vec3& force_world_n, double dt_s) noexcept {
  if (!std::isfinite(dt_s) || dt_s <= 0.0) {
    return;
  }
  Vec3 f = force_world_n;
  if (!f.allFinite()) {
    f.setZero();
    ++rejected_;
  }
  v_ += (f / params_.mass_kg + params_.gravity_m_per_s2) * dt_s;
  p_ += v_ * dt_s;
}

void RigidBall::hold(const Iso3& X_world_gripper, const Vec3& p_gripper_ball,
                     double dt_s) noexcept {
  const Vec3 p = X_world_gripper * p_gripper_ball;
  if (!p.allFinite()) {
    ++rejected_;
    return;  // keep the last good pose
  }
  v_ = held_ && std::isfinite(dt_s) && dt_s > 0.0 ? Vec3((p - p_) / dt_s) : Vec3::Zero();
  p_ = p;
  held_ = true;
}

}  // namespace hapsim
