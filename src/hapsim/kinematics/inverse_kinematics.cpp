#include "hapsim/kinematics/inverse_kinematics.h"

#include <Eigen/Cholesky>

#include <algorithm>
#include <cmath>

namespace hapsim {

namespace {

using Vec6 = Eigen::Matrix<double, 6, 1>;
using Mat6 = Eigen::Matrix<double, 6, 6>;

// Twist-like error taking `current` to `target`: position difference and the rotation vector of
// R_target·R_currentᵀ, both in the base frame (the frame of the geometric Jacobian).
Vec6 error_twist(const Iso3& current, const Iso3& target) {
  Vec6 e;
  e.head<3>() = target.translation() - current.translation();
  const Eigen::AngleAxisd aa(target.linear() * current.linear().transpose());
  e.tail<3>() = aa.angle() * aa.axis();
  return e;
}

// Deterministic start i ≥ 1: spread over the limits (a low-discrepancy sequence), within ±π for
// unlimited joints.
double start_value(const ChainJoint& j, int start, int joint) {
  const double golden = 0.6180339887498949;
  double u = std::fmod(0.5 + golden * (start * (joint + 3) + joint), 1.0);
  const double lo = std::isfinite(j.lower) ? j.lower : -3.14159265358979;
  const double hi = std::isfinite(j.upper) ? j.upper : 3.14159265358979;
  // Stay a little inside the limits, where the arm can still move both ways.
  u = 0.05 + 0.9 * u;
  return lo + u * (hi - lo);
}

}  // namespace

void pose_error(const Iso3& X_current, const Iso3& X_target, double* position_error_m,
                double* rotation_error_rad) noexcept {
  *position_error_m = (X_target.translation() - X_current.translation()).norm();
  *rotation_error_rad =
      Eigen::AngleAxisd(X_target.linear() * X_current.linear().transpose()).angle();
}

IkResult solve_ik(const SerialChain& chain, const Iso3& X_base_target,
                  std::span<const double> q_seed, std::span<double> q_out,
                  const IkOptions& options) noexcept {
  IkResult result;
  const int n = chain.dof();
  if (n == 0 || !X_base_target.matrix().allFinite()) {
    for (int i = 0; i < n; ++i) {
      q_out[static_cast<std::size_t>(i)] = q_seed[static_cast<std::size_t>(i)];
    }
    chain.clamp_to_limits(q_out);
    return result;
  }
  const double w = options.orientation ? options.rotation_weight_m : 0.0;
  const auto weighted = [&](const Vec6& e) {
    return std::sqrt(e.head<3>().squaredNorm() + w * w * e.tail<3>().squaredNorm());
  };
  const auto is_reached = [&](const Vec6& e) {
    return e.head<3>().norm() <= options.position_tolerance_m &&
           (!options.orientation || e.tail<3>().norm() <= options.rotation_tolerance_rad);
  };

  std::array<double, kMaxChainJoints> q{};
  std::array<double, kMaxChainJoints> trial{};
  std::array<double, kMaxChainJoints> best{};
  double best_cost = kInf;
  Vec6 best_error = Vec6::Constant(kInf);
  const std::span<double> qs(q.data(), static_cast<std::size_t>(n));
  const std::span<double> ts(trial.data(), static_cast<std::size_t>(n));

  for (int start = 0; start <= std::max(options.restarts, 0); ++start) {
    ++result.starts;
    for (int i = 0; i < n; ++i) {
      q[static_cast<std::size_t>(i)] =
          start == 0 ? q_seed[static_cast<std::size_t>(i)]
                     : start_value(chain.joints()[static_cast<std::size_t>(i)], start, i);
    }
    chain.clamp_to_limits(qs);
    Vec6 e = error_twist(chain.forward(qs), X_base_target);
    double cost = weighted(e);
    double lambda = options.damping;
    for (int it = 0; it < options.max_iterations && !is_reached(e); ++it) {
      ++result.iterations;
      ChainJacobian J = chain.jacobian(qs);
      Vec6 ew = e;
      J.bottomRows<3>() *= w;
      ew.tail<3>() *= w;
      const Mat6 A = J * J.transpose() + lambda * lambda * Mat6::Identity();
      ChainVector dq = ChainVector::Zero(n);  // sized first: GCC sees no uninitialised lanes
      dq.noalias() = J.transpose() * A.ldlt().solve(ew);
      const double largest = dq.cwiseAbs().maxCoeff();
      if (!std::isfinite(largest)) {
        break;
      }
      if (largest > options.max_step) {
        dq *= options.max_step / largest;
      }
      for (int i = 0; i < n; ++i) {
        trial[static_cast<std::size_t>(i)] = q[static_cast<std::size_t>(i)] + dq[i];
      }
      chain.clamp_to_limits(ts);
      const Vec6 e_trial = error_twist(chain.forward(ts), X_base_target);
      const double cost_trial = weighted(e_trial);
      if (cost_trial < cost) {
        std::copy(trial.begin(), trial.begin() + n, q.begin());
        e = e_trial;
        cost = cost_trial;
        lambda = std::max(lambda * 0.5, 1e-9);
      } else {
        lambda *= 4.0;  // towards gradient descent with a smaller step
        if (lambda > 1e3) {
          break;  // stuck (a limit or a singularity): try another start
        }
      }
    }
    if (cost < best_cost) {
      best_cost = cost;
      best_error = e;
      std::copy(q.begin(), q.begin() + n, best.begin());
    }
    if (is_reached(e)) {
      break;
    }
  }
  std::copy(best.begin(), best.begin() + n, q_out.begin());
  result.position_error_m = best_error.head<3>().norm();
  result.rotation_error_rad = best_error.tail<3>().norm();
  result.reached = is_reached(best_error);
  return result;
}

}  // namespace hapsim
