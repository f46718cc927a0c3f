#include "hapsim/script/palpation_trajectory.h"

#include "hapsim/core/error.h"

#include <algorithm>
#include <cmath>

#include <gtest/gtest.h>

namespace hapsim {
namespace {

std::vector<PalpationTarget> two_targets() {
  std::vector<PalpationTarget> targets(2);
  targets[0].p_world = Vec3(0.05, 0.0, 0.10);
  targets[0].press_dir_world = Vec3(0.0, 0.0, -2.0);  // not unit on purpose
  targets[0].depth_m = 0.008;
  targets[0].hold_s = 0.3;
  targets[1].p_world = Vec3(-0.02, 0.04, 0.12);
  targets[1].press_dir_world = Vec3(1.0, 0.0, -1.0);
  targets[1].depth_m = 0.004;
  targets[1].hold_s = 0.0;  // no hold phase
  return targets;
}

PalpationParams params() {
  PalpationParams p;
  p.start_p_world = Vec3(0.0, 0.0, 0.2);
  p.standoff_m = 0.015;
  p.move_s = 0.8;
  p.approach_s = 0.3;
  p.press_s = 0.4;
  p.release_s = 0.25;
  p.sample_period_s = 0.002;
  return p;
}

TEST(MinimumJerk, EndpointsAndSymmetry) {
  EXPECT_EQ(minimum_jerk(0.0), 0.0);
  EXPECT_EQ(minimum_jerk(1.0), 1.0);
  EXPECT_DOUBLE_EQ(minimum_jerk(0.5), 0.5);
  EXPECT_EQ(minimum_jerk(-1.0), 0.0);
  EXPECT_EQ(minimum_jerk(2.0), 1.0);
  for (double u = 0.0; u <= 1.0; u += 0.01) {
    EXPECT_NEAR(minimum_jerk(u) + minimum_jerk(1.0 - u), 1.0, 1e-14);
  }
}

TEST(PalpationTrajectory, PhasesInOrderAndTimed) {
  const auto targets = two_targets();
  const PalpationPlan plan = make_palpation_plan(targets, params());
  using K = PalpationPhaseKind;
  const std::vector<K> expected = {K::kMove, K::kApproach, K::kPress, K::kHold,   K::kRelease,
                                   K::kMove, K::kApproach, K::kPress, K::kRelease};
  ASSERT_EQ(plan.phases.size(), expected.size());
  double t = 0.0;
  for (std::size_t i = 0; i < expected.size(); ++i) {
    EXPECT_EQ(plan.phases[i].kind, expected[i]) << i;
    EXPECT_DOUBLE_EQ(plan.phases[i].start_s, t);
    t = plan.phases[i].end_s;
  }
  EXPECT_NEAR(plan.trajectory.end_time_s(), 2 * (0.8 + 0.3 + 0.4 + 0.25) + 0.3, 1e-12);
  EXPECT_EQ(plan.trajectory.samples.front().p_world, params().start_p_world);
}

TEST(PalpationTrajectory, ReachesEachTargetDepthAndNoDeeper) {
  const auto targets = two_targets();
  const PalpationPlan plan = make_palpation_plan(targets, params());
  for (std::size_t i = 0; i < targets.size(); ++i) {
    SCOPED_TRACE(i);
    const Vec3 dir = targets[i].press_dir_world.normalized();
    const Vec3 pressed = targets[i].p_world + targets[i].depth_m * dir;
    // Deepest point along the press direction, over every sample of the whole run.
    double deepest_m = -kInf;
    for (const DeviceInput& s : plan.trajectory.samples) {
      if ((s.p_world - targets[i].p_world).cross(dir).norm() < 1e-9) {  // on this target's axis
        deepest_m = std::max(deepest_m, (s.p_world - targets[i].p_world).dot(dir));
      }
    }
    EXPECT_NEAR(deepest_m, targets[i].depth_m, 1e-12);
    // Exactly the pressed point at the end of the press phase.
    const auto press = std::find_if(plan.phases.begin(), plan.phases.end(), [&](const auto& p) {
      return p.kind == PalpationPhaseKind::kPress && p.target_index == static_cast<int>(i);
    });
    ASSERT_NE(press, plan.phases.end());
    EXPECT_EQ(plan.trajectory.sample_at(press->end_s).p_world, pressed);
    EXPECT_EQ(press->to_p_world, pressed);
    // Held there for hold_s.
    if (targets[i].hold_s > 0.0) {
      EXPECT_EQ(plan.trajectory.sample_at(press->end_s + 0.5 * targets[i].hold_s).p_world, pressed);
    }
  }
}

// Minimum jerk: peak speed 1.875 D/T, peak acceleration (10/sqrt(3)) D/T^2. The sampled path
// must respect both, which a linear (constant-velocity) profile would not: its velocity jumps.
TEST(PalpationTrajectory, SmoothWithBoundedVelocityAndAcceleration) {
  const auto targets = two_targets();
  const PalpationPlan plan = make_palpation_plan(targets, params());
  double v_max = 0.0;
  double a_max = 0.0;
  for (const PalpationPhase& p : plan.phases) {
    const double d = (p.to_p_world - p.from_p_world).norm();
    const double t = p.end_s - p.start_s;
    v_max = std::max(v_max, 1.875 * d / t);
    a_max = std::max(a_max, 10.0 / std::sqrt(3.0) * d / (t * t));
  }
  ASSERT_GT(v_max, 0.0);
  const auto& s = plan.trajectory.samples;
  std::vector<Vec3> v;  // mean velocity over each interval
  std::vector<double> dt;
  for (std::size_t i = 1; i < s.size(); ++i) {
    dt.push_back(s[i].time_s - s[i - 1].time_s);
    v.emplace_back((s[i].p_world - s[i - 1].p_world) / dt.back());
    if (dt.back() > params().sample_period_s + 1e-12) {
      // Only a hold may be one long interval, and it does not move.
      EXPECT_EQ(s[i].p_world, s[i - 1].p_world) << "long interval " << i << " moves";
      continue;
    }
    EXPECT_LE(v.back().norm(), v_max * (1 + 1e-9)) << "interval " << i;
  }
  // Mean velocities of neighbouring intervals differ by at most a_max times their span.
  for (std::size_t i = 1; i < v.size(); ++i) {
    if (dt[i] > params().sample_period_s + 1e-12 || dt[i - 1] > params().sample_period_s + 1e-12) {
      continue;  // a hold is one long interval at rest
    }
    EXPECT_LE((v[i] - v[i - 1]).norm(), a_max * (dt[i] + dt[i - 1]) * (1 + 1e-6)) << i;
  }
  // Played back at the haptic rate, the probe never outruns the profile either.
  Vec3 previous = plan.trajectory.sample_at(0.0).p_world;
  for (double t = 0.001; t <= plan.trajectory.end_time_s(); t += 0.001) {
    const Vec3 p = plan.trajectory.sample_at(t).p_world;
    EXPECT_LE((p - previous).norm() / 0.001, v_max * (1 + 1e-6)) << t;
    previous = p;
  }
}

TEST(PalpationTrajectory, RejectsBadParameters) {
  const auto targets = two_targets();
  EXPECT_THROW((void)make_palpation_plan({}, params()), Error);
  PalpationParams p = params();
  p.press_s = 0.0;
  EXPECT_THROW((void)make_palpation_plan(targets, p), Error);
  p = params();
  p.sample_period_s = std::nan("");
  EXPECT_THROW((void)make_palpation_plan(targets, p), Error);
  auto bad = targets;
  bad[1].press_dir_world = Vec3::Zero();
  try {
    (void)make_palpation_plan(bad, params());
    FAIL();
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("target 1"), std::string::npos) << e.what();
  }
  bad = targets;
  bad[0].depth_m = -0.001;
  EXPECT_THROW((void)make_palpation_plan(bad, params()), Error);
}

// Targets on opposite sides of a limb along z: a straight move would pass through its axis; the
// move round the axis never comes closer to it than the stand-offs, and still ends exactly there.
TEST(PalpationTrajectory, MovesGoRoundTheAxisInsteadOfThroughTheBody) {
  std::vector<PalpationTarget> targets(2);
  targets[0].p_world = Vec3(0.05, 0.0, 0.02);
  targets[0].press_dir_world = -Vec3::UnitX();
  targets[1].p_world = Vec3(-0.05, 0.001, -0.03);
  targets[1].press_dir_world = Vec3::UnitX();
  PalpationParams p = params();
  p.start_p_world = Vec3(0.1, 0.0, 0.02);
  p.around_point_world = Vec3(0.0, 0.0, 0.1);  // any point on the axis
  p.around_axis_world = Vec3(0.0, 0.0, 2.0);   // normalised by the planner
  p.around_radius_m = 0.09;
  const PalpationPlan plan = make_palpation_plan(targets, p);
  const auto move = std::find_if(plan.phases.begin(), plan.phases.end(), [](const auto& ph) {
    return ph.kind == PalpationPhaseKind::kMove && ph.target_index == 1;
  });
  ASSERT_NE(move, plan.phases.end());
  const double standoff_r = 0.05 + p.standoff_m;
  double least_r = kInf;
  double most_r = 0.0;
  for (const DeviceInput& s : plan.trajectory.samples) {
    if (s.time_s >= move->start_s && s.time_s <= move->end_s) {
      const double r = std::hypot(s.p_world.x(), s.p_world.y());
      least_r = std::min(least_r, r);
      most_r = std::max(most_r, r);
    }
  }
  EXPECT_GE(least_r, standoff_r - 0.002);  // the second stand-off is 1 mm off the x axis
  EXPECT_NEAR(most_r, 0.09, 1e-9);         // round on the cylinder
  EXPECT_EQ(plan.trajectory.sample_at(move->end_s).p_world,
            targets[1].p_world - p.standoff_m * Vec3::UnitX());
  // Without the cylinder the same move goes straight through the axis.
  p.around_radius_m = 0.0;
  const PalpationPlan straight = make_palpation_plan(targets, p);
  double straight_least = kInf;
  for (const DeviceInput& s : straight.trajectory.samples) {
    straight_least = std::min(straight_least, std::hypot(s.p_world.x(), s.p_world.y()));
  }
  EXPECT_LT(straight_least, 0.005);
  p.around_radius_m = 0.09;
  p.around_axis_world = Vec3::Zero();
  EXPECT_THROW((void)make_palpation_plan(targets, p), Error);
}

}  // namespace
}  // namespace hapsim
