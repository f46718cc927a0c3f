#include "hapsim/device/palpation_trajectory.h"

#include "hapsim/core/error.h"

#include <algorithm>
#include <cmath>
#include <string>

namespace hapsim {
namespace {

constexpr const char* kWhere = "palpation trajectory";

void require_positive(double value, const char* name) {
  if (!(std::isfinite(value) && value > 0.0)) {
    throw Error(kWhere, std::string(name) + " = " + std::to_string(value) +
                            ", expected a finite value > 0");
  }
}

void require_non_negative(double value, const std::string& name) {
  if (!(std::isfinite(value) && value >= 0.0)) {
    throw Error(kWhere, name + " = " + std::to_string(value) + ", expected a finite value >= 0");
  }
}

class PlanBuilder {
 public:
  explicit PlanBuilder(const PalpationParams& params) : params_(params) {
    DeviceInput first;
    first.time_s = 0.0;
    first.p_world = params.start_p_world;
    first.q_world = params.q_world;
    samples_.push_back(first);
  }

  // One minimum-jerk motion from the current position to `to_p_world` over `duration_s`
  // (a stationary hold when they are equal).
  void phase(PalpationPhaseKind kind, int target, const Vec3& to_p_world, double duration_s) {
    const DeviceInput last = samples_.back();
    const Vec3 from = last.p_world;
    const bool moving = from != to_p_world;
    // Uniform steps no longer than the sample period; a hold needs only its end point.
    const int steps =
        moving
            ? std::max(1, static_cast<int>(std::ceil(duration_s / params_.sample_period_s - 1e-9)))
            : 1;
    for (int k = 1; k <= steps; ++k) {
      const double u = static_cast<double>(k) / steps;
      DeviceInput s = last;
      s.time_s = last.time_s + duration_s * u;
      // The end point is set exactly so phases join without rounding drift.
      s.p_world = k == steps ? to_p_world : Vec3(from + minimum_jerk(u) * (to_p_world - from));
      samples_.push_back(s);
    }
    phases_.push_back({kind, target, last.time_s, samples_.back().time_s, from, to_p_world});
  }

  PalpationPlan finish() {
    PalpationPlan plan;
    plan.trajectory = make_trajectory(std::move(samples_), 0, 0, kWhere);
    plan.phases = std::move(phases_);
    return plan;
  }

 private:
  const PalpationParams& params_;
  std::vector<DeviceInput> samples_;
  std::vector<PalpationPhase> phases_;
};

}  // namespace

double minimum_jerk(double u) noexcept {
  const double x = std::clamp(u, 0.0, 1.0);
  const double x3 = x * x * x;
  return x3 * (10.0 + x * (-15.0 + 6.0 * x));
}

PalpationPlan make_palpation_plan(std::span<const PalpationTarget> targets,
                                  const PalpationParams& params) {
  if (targets.empty()) {
    throw Error(kWhere, "no targets; expected at least one");
  }
  require_positive(params.move_s, "move_s");
  require_positive(params.approach_s, "approach_s");
  require_positive(params.press_s, "press_s");
  require_positive(params.release_s, "release_s");
  require_positive(params.sample_period_s, "sample_period_s");
  require_non_negative(params.standoff_m, "standoff_m");
  if (!params.start_p_world.allFinite()) {
    throw Error(kWhere, "start_p_world is not finite");
  }
  PlanBuilder builder(params);
  for (std::size_t i = 0; i < targets.size(); ++i) {
    const PalpationTarget& target = targets[i];
    const std::string name = "target " + std::to_string(i);
    const double dir_norm = target.press_dir_world.norm();
    if (!target.p_world.allFinite() || !std::isfinite(dir_norm) || dir_norm < 1e-12) {
      throw Error(kWhere, name +
                              ": position and press direction must be finite and the "
                              "direction non-zero");
    }
    require_non_negative(target.depth_m, name + " depth_m");
    require_non_negative(target.hold_s, name + " hold_s");
    const Vec3 dir = target.press_dir_world / dir_norm;
    const Vec3 standoff = target.p_world - params.standoff_m * dir;
    const Vec3 pressed = target.p_world + target.depth_m * dir;
    const int index = static_cast<int>(i);
    builder.phase(PalpationPhaseKind::kMove, index, standoff, params.move_s);
    builder.phase(PalpationPhaseKind::kApproach, index, target.p_world, params.approach_s);
    builder.phase(PalpationPhaseKind::kPress, index, pressed, params.press_s);
    if (target.hold_s > 0.0) {
      builder.phase(PalpationPhaseKind::kHold, index, pressed, target.hold_s);
    }
    builder.phase(PalpationPhaseKind::kRelease, index, standoff, params.release_s);
  }
  return builder.finish();
}

}  // namespace hapsim
