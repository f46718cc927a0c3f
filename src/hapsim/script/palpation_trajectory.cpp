#include "hapsim/script/palpation_trajectory.h"

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

  // A minimum-jerk motion along a path given by `at(arc length)` of total length `length_m`.
  template <typename PathFn>
  void phase_along(PalpationPhaseKind kind, int target, double length_m, const PathFn& at,
                   double duration_s) {
    const DeviceInput last = samples_.back();
    const Vec3 to = at(length_m);
    const int steps =
        std::max(1, static_cast<int>(std::ceil(duration_s / params_.sample_period_s - 1e-9)));
    for (int k = 1; k <= steps; ++k) {
      const double u = static_cast<double>(k) / steps;
      DeviceInput s = last;
      s.time_s = last.time_s + duration_s * u;
      s.p_world = k == steps ? to : at(minimum_jerk(u) * length_m);
      samples_.push_back(s);
    }
    phases_.push_back({kind, target, last.time_s, samples_.back().time_s, last.p_world, to});
  }

  // The move to `to_p_world`: straight, or out to the cylinder, round it, and in.
  void move(int target, const Vec3& to_p_world) {
    const Vec3 from = samples_.back().p_world;
    if (!(params_.around_radius_m > 0.0) || from == to_p_world) {
      phase(PalpationPhaseKind::kMove, target, to_p_world, params_.move_s);
      return;
    }
    const Vec3 axis = params_.around_axis_world.normalized();
    const Vec3 c = params_.around_point_world;
    // Radial part (perpendicular to the axis) and height along it of a point.
    const auto radial = [&](const Vec3& p) { return Vec3((p - c) - (p - c).dot(axis) * axis); };
    const Vec3 r0 = radial(from);
    const Vec3 r1 = radial(to_p_world);
    const double R = std::max({params_.around_radius_m, r0.norm(), r1.norm()});
    if (r0.norm() < 1e-9 || r1.norm() < 1e-9) {
      phase(PalpationPhaseKind::kMove, target, to_p_world, params_.move_s);
      return;
    }
    const Vec3 u0 = r0.normalized();
    const Vec3 u1 = r1.normalized();
    const Vec3 a = from + (R - r0.norm()) * u0;        // out
    const Vec3 b = to_p_world + (R - r1.norm()) * u1;  // the point above the next stand-off
    const double angle = std::atan2(u0.cross(u1).dot(axis), u0.dot(u1));  // signed, about axis
    const double h0 = (a - c).dot(axis);
    const double h1 = (b - c).dot(axis);
    const double l_out = (a - from).norm();
    const double l_arc = std::hypot(R * angle, h1 - h0);
    const double l_in = (to_p_world - b).norm();
    const auto at = [&](double x) -> Vec3 {
      if (x <= l_out) {
        return l_out > 0.0 ? Vec3(from + (a - from) * (x / l_out)) : a;
      }
      x -= l_out;
      if (x <= l_arc) {
        const double f = l_arc > 0.0 ? x / l_arc : 1.0;
        const Vec3 u = Eigen::AngleAxisd(f * angle, axis) * u0;
        return c + (h0 + f * (h1 - h0)) * axis + R * u;
      }
      x -= l_arc;
      return l_in > 0.0 ? Vec3(b + (to_p_world - b) * std::min(1.0, x / l_in)) : to_p_world;
    };
    phase_along(PalpationPhaseKind::kMove, target, l_out + l_arc + l_in, at, params_.move_s);
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
  require_non_negative(params.around_radius_m, "around_radius_m");
  if (params.around_radius_m > 0.0 &&
      (!params.around_point_world.allFinite() || !params.around_axis_world.allFinite() ||
       params.around_axis_world.norm() < 1e-12)) {
    throw Error(kWhere,
                "around_point_world and around_axis_world must be finite, the axis "
                "non-zero");
  }
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
    builder.move(index, standoff);
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
