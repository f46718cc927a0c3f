// A scripted palpation: for each target, move to a stand-off point above it, approach the
// surface, press in to a depth, hold, release back to the stand-off, then on to the next target.
// Every motion follows a minimum-jerk profile (zero velocity and acceleration at both ends), so
// the probe never jerks and a scene can ship an unattended palpation run.
#pragma once

#include "hapsim/script/trajectory.h"

#include <span>
#include <vector>

namespace hapsim {

struct PalpationTarget {
  /// Surface point to press, world frame, metres.
  Vec3 p_world = Vec3::Zero();
  /// Pressing direction (into the surface), world frame; normalised by the generator.
  Vec3 press_dir_world = -Vec3::UnitZ();
  /// How far past p_world to press, metres (>= 0).
  double depth_m = 0.005;
  /// How long to hold at depth, seconds (>= 0).
  double hold_s = 0.5;
};

struct PalpationParams {
  /// Where the probe starts, world frame.
  Vec3 start_p_world = Vec3::Zero();
  /// Probe orientation, held constant.
  Quat q_world = Quat::Identity();
  /// Stand-off distance above each target (against press_dir), metres (>= 0).
  double standoff_m = 0.02;
  /// Phase durations, seconds (> 0).
  double move_s = 1.0;
  double approach_s = 0.5;
  double press_s = 0.5;
  double release_s = 0.5;
  /// Moves between targets go around the body instead of straight through it: out to
  /// `around_radius_m` from the axis through `around_point_world` along `around_axis_world`, round
  /// the axis on that cylinder, and in to the next stand-off. Off while the radius is 0 (a limb
  /// is long along its axis, so a cylinder hugs it far better than a bounding sphere).
  Vec3 around_point_world = Vec3::Zero();
  Vec3 around_axis_world = Vec3::UnitZ();
  double around_radius_m = 0.0;
  /// Longest spacing between samples of a moving phase, seconds (> 0). 1 ms matches the haptic
  /// rate, so linear interpolation between samples adds no visible error.
  double sample_period_s = 0.001;
};

enum class PalpationPhaseKind { kMove, kApproach, kPress, kHold, kRelease };

struct PalpationPhase {
  PalpationPhaseKind kind = PalpationPhaseKind::kMove;
  int target_index = 0;
  double start_s = 0.0;
  double end_s = 0.0;
  Vec3 from_p_world = Vec3::Zero();
  Vec3 to_p_world = Vec3::Zero();
};

struct PalpationPlan {
  Trajectory trajectory;
  /// The phases in time order; a scene report uses them ("target 2 pressed at 3.5 s").
  std::vector<PalpationPhase> phases;
};

/// Minimum-jerk position fraction s(u) = 10u^3 - 15u^4 + 6u^5 for u in [0, 1] (clamped).
[[nodiscard]] double minimum_jerk(double u) noexcept;

/// Builds the plan, starting at time 0 at params.start_p_world. Throws hapsim::Error
/// ("palpation trajectory") for no targets, non-positive durations or a zero press direction.
[[nodiscard]] PalpationPlan make_palpation_plan(std::span<const PalpationTarget> targets,
                                                const PalpationParams& params);

}  // namespace hapsim
