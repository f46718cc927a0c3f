// A rigid ball under gravity (the object the teleoperated slave picks and places): position and
// velocity integrated by semi-implicit (symplectic) Euler, v += (F/m + g)·dt then p += v·dt,
// which is stable for the stiff penalty contacts at 1 kHz where explicit Euler gains energy.
// While a gripper holds it, it moves with the gripper instead (held_by()).
#pragma once

#include "hapsim/core/types.h"

#include <cstddef>

namespace hapsim {

struct RigidBallParams {
  double mass_kg = 0.1;
  double radius_m = 0.03;
  Vec3 gravity_m_per_s2 = Vec3(0.0, 0.0, -9.81);
};

class RigidBall {
 public:
  /// Throws hapsim::Error on a non-positive or non-finite mass or radius, or a non-finite start.
  RigidBall(RigidBallParams params, const Vec3& p_world, const Vec3& v_world = Vec3::Zero());

  /// One free step under gravity and `force_world_n` (the sum of contact forces). A non-finite
  /// force is dropped (counted): the ball never becomes NaN. haptic path
  void step(const Vec3& force_world_n, double dt_s) noexcept;

  /// Held: the ball sits at `X_world_gripper · p_gripper_ball`, its velocity the change since the
  /// last call. Call every cycle while held, then release() to fly free again. haptic path
  void hold(const Iso3& X_world_gripper, const Vec3& p_gripper_ball, double dt_s) noexcept;
  void release() noexcept { held_ = false; }
  [[nodiscard]] bool held() const { return held_; }

  [[nodiscard]] const Vec3& p_world() const { return p_; }
  [[nodiscard]] const Vec3& v_world() const { return v_; }
  [[nodiscard]] const RigidBallParams& params() const { return params_; }
  [[nodiscard]] double kinetic_energy_j() const { return 0.5 * params_.mass_kg * v_.squaredNorm(); }
  [[nodiscard]] std::size_t rejected_forces() const { return rejected_; }

 private:
  RigidBallParams params_;
  Vec3 p_;
  Vec3 v_;
  bool held_ = false;
  std::size_t rejected_ = 0;
};

}  // namespace hapsim
