// Inverse kinematics by damped least squares (Levenberg–Marquardt on the pose error) with joint
// limits: dq = Jᵀ(J·Jᵀ + λ²I)⁻¹·e, steps clamped into the limits, λ raised when a step makes the
// error worse and lowered when it helps. Starts from the seed (last cycle's answer when
// tracking), then from a few deterministic spread-out starts if that does not converge; answers
// whether the target was reached within tolerance. Allocation-free: a slave can call it every
// haptic cycle.
#pragma once

#include "hapsim/kinematics/serial_chain.h"

#include <span>

namespace hapsim {

struct IkOptions {
  /// Reached when the tip is this close to the target, metres and radians (0.1 mm, 0.05°).
  double position_tolerance_m = 1e-4;
  double rotation_tolerance_rad = 8.7e-4;
  /// Match the orientation too (false: position only, for chains with fewer than 6 joints).
  bool orientation = true;
  /// How a radian of orientation error weighs against a metre of position error.
  double rotation_weight_m = 0.1;
  /// Iterations per start, and extra starts after the seed.
  int max_iterations = 100;
  int restarts = 16;
  /// Initial damping λ (metres); adapts per iteration.
  double damping = 1e-3;
  /// Largest joint change per iteration, rad or m.
  double max_step = 0.5;
};

struct IkResult {
  bool reached = false;
  int iterations = 0;  // over all starts
  int starts = 0;
  double position_error_m = kInf;
  double rotation_error_rad = kInf;
};

/// Solves for joint values `q_out` (dof() values, within limits) that put the tip at
/// `X_base_target`. `q_seed` (dof() values) is the first start. When not reached, q_out holds
/// the best pose found (least weighted error). haptic path (no allocation).
IkResult solve_ik(const SerialChain& chain, const Iso3& X_base_target,
                  std::span<const double> q_seed, std::span<double> q_out,
                  const IkOptions& options = {}) noexcept;

/// Position and rotation error between two poses (metres, radians).
void pose_error(const Iso3& X_current, const Iso3& X_target, double* position_error_m,
                double* rotation_error_rad) noexcept;

}  // namespace hapsim
