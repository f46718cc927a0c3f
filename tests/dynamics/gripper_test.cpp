// The parallel gripper: closing on a ball resting on the floor grasps it when friction can carry
// its weight, the pads stop at the gripper's force limit, the ball rides with the gripper while
// held, falls when the pads open; one pad alone, or a weak grip, holds nothing.
#include "hapsim/dynamics/ball_environment.h"
#include "hapsim/dynamics/parallel_gripper.h"

#include "hapsim/core/error.h"

#include <gtest/gtest.h>

#include <cmath>

namespace hapsim {
namespace {

constexpr double kDt = 1e-3;

// Tool z pointing down, y the closing direction; the pads' centres 7 cm below the flange.
Iso3 tool_at(const Vec3& flange) {
  Iso3 X = Iso3::Identity();
  X.linear() = (Mat3() << 1, 0, 0, 0, -1, 0, 0, 0, -1).finished();
  X.translation() = flange;
  return X;
}

struct Bench {
  VirtualSheet sheet{};
  BallEnvironment env{sheet, [] {
                        BallEnvironmentOptions o;
                        o.X_world_sheet = Iso3(Eigen::Translation3d(1.0, 0.0, -0.05));  // aside
                        o.floor_z_m = 0.0;
                        return o;
                      }()};
  RigidBall ball{RigidBallParams{}, Vec3(0.0, 0.0, 0.03)};
  ParallelGripper gripper;

  GripperReport cycle(const Iso3& tool, double width) {
    const GripperReport g = gripper.step(tool, width, ball, kDt);
    (void)env.step(ball, g.force_on_ball_world_n, kDt);
    return g;
  }
  void settle() {
    for (int k = 0; k < 500; ++k) {
      (void)env.step(ball, Vec3::Zero(), kDt);
    }
  }
};

TEST(ParallelGripper, GraspsLiftsAndReleases) {
  Bench b;
  b.settle();
  const double r = b.ball.params().radius_m;
  const Vec3 flange(0.0, 0.0, b.ball.p_world().z() + b.gripper.params().pad_depth_m);
  const Iso3 tool = tool_at(flange);
  // Close from 10 cm to 0 over 0.4 s.
  int grasped_at = -1;
  GripperReport g;
  for (int k = 0; k < 400; ++k) {
    g = b.cycle(tool, 0.1 * (1.0 - k / 400.0));
    if (g.grasped_now) {
      grasped_at = k;
    }
    EXPECT_LE(g.pad_force_n[0], b.gripper.params().max_force_n * 1.01) << k;
  }
  ASSERT_GE(grasped_at, 0);
  EXPECT_TRUE(g.held);
  // Closed against the ball at the force limit: width = 2·(r − F_max/k).
  const double pen_max =
      b.gripper.params().max_force_n / b.gripper.params().pad_contact.stiffness_n_per_m;
  EXPECT_NEAR(g.width_m, 2.0 * (r - pen_max) + 2.0 * std::abs(b.ball.p_world().y()), 1e-9);
  EXPECT_NEAR(g.pad_force_n[0], b.gripper.params().max_force_n, 0.05);
  EXPECT_NEAR(g.grasp_force_n(), b.gripper.params().max_force_n, 0.05);
  // Lift 10 cm in 0.5 s: the ball rides along.
  const Vec3 before = b.ball.p_world();
  for (int k = 1; k <= 500; ++k) {
    g = b.cycle(tool_at(flange + Vec3(0, 0, 0.1 * k / 500.0)), 0.0);
    ASSERT_TRUE(g.held) << k;
  }
  EXPECT_NEAR(b.ball.p_world().z() - before.z(), 0.1, 1e-9);
  // Open: released at once, then it falls back to the floor.
  g = b.cycle(tool_at(flange + Vec3(0, 0, 0.1)), 0.1);
  EXPECT_TRUE(g.released_now);
  EXPECT_FALSE(g.held);
  for (int k = 0; k < 1500; ++k) {
    g = b.cycle(tool_at(flange + Vec3(0, 0, 0.1)), 0.1);
  }
  EXPECT_FALSE(g.held);
  EXPECT_NEAR(b.ball.p_world().z(), r, 1e-3);
  EXPECT_LT(b.ball.kinetic_energy_j(), 1e-8);
}

// Pressing down on the top of the ball with closed pads: both touch, but from the same side —
// no opposing pads, no grasp; the ball is pushed into the floor.
TEST(ParallelGripper, PressingFromAboveIsNoGrasp) {
  Bench b;
  b.settle();
  const double top = b.ball.p_world().z() + b.ball.params().radius_m;
  const double pad_bottom = b.gripper.params().pad_depth_m + b.gripper.params().pad_half_m.z();
  bool ever_held = false;
  for (int k = 0; k < 300; ++k) {
    const double press = 0.004 * k / 300.0;  // 4 mm into the ball's top
    const GripperReport g = b.cycle(tool_at(Vec3(0, 0, top + pad_bottom - press)), 0.0);
    ever_held = ever_held || g.held;
  }
  EXPECT_FALSE(ever_held);
  EXPECT_LT(b.ball.p_world().z(), b.ball.params().radius_m - 1e-4);  // squashed into the floor
}

TEST(ParallelGripper, AWeakGripHoldsNothing) {
  Bench b;
  b.settle();
  ParallelGripperParams weak;
  weak.max_force_n = 0.5;  // μ·2·0.5 N = 0.8 N < 1.5 · 0.98 N
  b.gripper = ParallelGripper(weak);
  const Vec3 flange(0.0, 0.0, b.ball.p_world().z() + weak.pad_depth_m);
  bool ever_held = false;
  for (int k = 0; k < 400; ++k) {
    ever_held = ever_held || b.cycle(tool_at(flange), 0.1 * (1.0 - k / 400.0)).held;
  }
  EXPECT_FALSE(ever_held);
  EXPECT_THROW(ParallelGripper(ParallelGripperParams{.max_force_n = 0.0}), Error);
}

}  // namespace
}  // namespace hapsim
