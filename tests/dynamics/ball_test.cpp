// The ball: falls with g (analytic over 0.2 s), comes to rest on the sheet without jitter with
// the sheet carrying its weight, the sheet's surface shows the ball's lower cap exactly, rests on
// the floor at its spring's sag, follows a gripper while held and falls when released, and never
// turns NaN.
#include "hapsim/dynamics/ball_environment.h"
#include "hapsim/dynamics/rigid_ball.h"

#include "hapsim/core/error.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>

namespace hapsim {
namespace {

constexpr double kG = 9.81;
constexpr double kDt = 1e-3;

TEST(RigidBall, FallsWithG) {
  RigidBall ball({}, Vec3(0, 0, 1.0));
  for (int k = 0; k < 200; ++k) {
    ball.step(Vec3::Zero(), kDt);
  }
  const double t = 0.2;
  EXPECT_NEAR(ball.v_world().z(), -kG * t, 1e-12);  // exact for constant acceleration
  // Semi-implicit Euler runs ahead of z0 − g t²/2 by g·dt·t/2 (first order in dt): ~1 mm here.
  const double analytic = 1.0 - 0.5 * kG * t * t;
  EXPECT_NEAR(ball.p_world().z(), analytic - 0.5 * kG * kDt * t, 1e-12);
  EXPECT_LT(std::abs(ball.p_world().z() - analytic), 1.0e-3);
  EXPECT_EQ(ball.p_world().x(), 0.0);
}

TEST(RigidBall, BadInputNeverMakesNaN) {
  EXPECT_THROW(RigidBall(RigidBallParams{.mass_kg = 0.0}, Vec3::Zero()), Error);
  EXPECT_THROW(RigidBall(RigidBallParams{.radius_m = -1.0}, Vec3::Zero()), Error);
  RigidBall ball({}, Vec3(0, 0, 1.0));
  ball.step(Vec3(std::numeric_limits<double>::quiet_NaN(), 0, 0), kDt);
  ball.step(Vec3::Zero(), std::numeric_limits<double>::infinity());
  EXPECT_TRUE(ball.p_world().allFinite());
  EXPECT_TRUE(ball.v_world().allFinite());
  EXPECT_EQ(ball.rejected_forces(), 1u);
}

// The paper's sheet (16×16, Gaussian, 3 N/mm) 0.2 m wide at z = 0, the ball dropped from 5 cm.
struct Drop {
  VirtualSheet sheet{};
  BallEnvironment env{sheet};
  RigidBall ball{RigidBallParams{}, Vec3(0.004, -0.003, 0.08)};
};

TEST(BallEnvironment, ComesToRestOnTheSheetWithoutJitter) {
  Drop d;
  BallContactReport last;
  for (int k = 0; k < 2000; ++k) {
    last = d.env.step(d.ball, Vec3::Zero(), kDt);
  }
  ASSERT_TRUE(last.on_sheet);
  EXPECT_FALSE(last.on_floor);
  const Vec3 settled = d.ball.p_world();
  double most_energy = 0.0;
  double farthest = 0.0;
  for (int k = 0; k < 1000; ++k) {
    last = d.env.step(d.ball, Vec3::Zero(), kDt);
    most_energy = std::max(most_energy, d.ball.kinetic_energy_j());
    farthest = std::max(farthest, (d.ball.p_world() - settled).norm());
  }
  EXPECT_LT(most_energy, 1e-10);  // J: a speed below ~45 µm/s
  EXPECT_LT(farthest, 1e-6);      // m
  // The sheet carries the weight, and sinks as the profile says for that force.
  const double weight = d.ball.params().mass_kg * kG;
  EXPECT_NEAR(last.sheet_force_world_n.z(), weight, 1e-3 * weight);
  EXPECT_NEAR(last.sheet_push_n, weight, 1e-3 * weight);
  // Every node of the elastic field at the profile's depth for that push at that node's distance
  // from the contact point, which lies under the ball.
  EXPECT_LT((last.sheet_contact_sheet.head<2>() - settled.head<2>()).norm(), 1e-3);
  const int n = d.sheet.nodes_per_side();
  const double half = 0.5 * d.sheet.side_m();
  EXPECT_GT(d.sheet.profile().depth_m(0.0, weight), 1e-4);  // a visible dent: > 0.1 mm
  for (int j = 0; j < n; ++j) {
    for (int i = 0; i < n; ++i) {
      const Eigen::Vector2d node(-half + i * d.sheet.spacing_m(), -half + j * d.sheet.spacing_m());
      const double distance = (node - last.sheet_contact_sheet.head<2>()).norm();
      EXPECT_NEAR(-d.sheet.elastic_heights()[static_cast<std::size_t>(j * n + i)],
                  d.sheet.profile().depth_m(distance, last.sheet_push_n), 1e-15)
          << i << "," << j;
    }
  }
  // The ball sits on the sheet: its bottom is one contact-spring sag into the elastic field.
  const double spring_sag = weight / d.env.options().sheet_contact.stiffness_n_per_m;
  EXPECT_NEAR(settled.z() - d.ball.params().radius_m,
              d.sheet.height_at(settled.x(), settled.y(), SheetLayer::kElastic) - spring_sag, 2e-5);
}

TEST(BallEnvironment, SurfaceShowsTheBallsLowerCap) {
  Drop d;
  for (int k = 0; k < 2000; ++k) {
    (void)d.env.step(d.ball, Vec3::Zero(), kDt);
  }
  const Vec3 c = d.ball.p_world();  // sheet frame = world here
  const double r = d.ball.params().radius_m;
  const int n = d.sheet.nodes_per_side();
  const double half = 0.5 * d.sheet.side_m();
  int imprinted = 0;
  for (int j = 0; j < n; ++j) {
    for (int i = 0; i < n; ++i) {
      const double x = -half + i * d.sheet.spacing_m(), y = -half + j * d.sheet.spacing_m();
      const auto idx = static_cast<std::size_t>(j * n + i);
      const double elastic = d.sheet.elastic_heights()[idx];
      const double d2 = (x - c.x()) * (x - c.x()) + (y - c.y()) * (y - c.y());
      double expected = elastic;
      if (d2 < r * r) {
        expected = std::min(elastic, c.z() - std::sqrt(r * r - d2));
      }
      EXPECT_NEAR(d.sheet.surface_heights()[idx], expected, 1e-12) << i << "," << j;
      imprinted += d.sheet.surface_heights()[idx] < elastic ? 1 : 0;
    }
  }
  EXPECT_GE(imprinted, 1);  // the cap does reach below the elastic dent somewhere
}

TEST(BallEnvironment, RestsOnTheFloorBesideTheSheet) {
  VirtualSheet sheet;
  BallEnvironment env(sheet);
  RigidBall ball({}, Vec3(0.5, 0.0, 0.0));  // 0.5 m away from the 0.2 m sheet
  for (int k = 0; k < 3000; ++k) {
    (void)env.step(ball, Vec3::Zero(), kDt);
  }
  const double weight = ball.params().mass_kg * kG;
  EXPECT_NEAR(ball.p_world().z(),
              env.options().floor_z_m + ball.params().radius_m -
                  weight / env.options().floor_contact.stiffness_n_per_m,
              1e-7);
  EXPECT_LT(ball.kinetic_energy_j(), 1e-10);
  EXPECT_EQ(sheet.max_depth_m(), 0.0);  // the sheet never felt it
}

TEST(BallEnvironment, HeldBallFollowsTheGripperAndFallsWhenReleased) {
  Drop d;
  const Vec3 in_gripper(0.0, 0.0, -0.05);
  for (int k = 0; k <= 100; ++k) {
    const Iso3 gripper(Eigen::Translation3d(0.001 * k, 0.0, 0.3));
    d.ball.hold(gripper, in_gripper, kDt);
    (void)d.env.step(d.ball, Vec3::Zero(), kDt);
    ASSERT_NEAR((d.ball.p_world() - gripper * in_gripper).norm(), 0.0, 1e-15);
  }
  EXPECT_NEAR(d.ball.v_world().x(), 1.0, 1e-9);  // 1 mm per 1 ms cycle
  d.ball.release();
  const double z0 = d.ball.p_world().z();
  for (int k = 0; k < 100; ++k) {
    (void)d.env.step(d.ball, Vec3::Zero(), kDt);
  }
  EXPECT_LT(d.ball.p_world().z(), z0 - 0.04);  // ~0.049 m after 0.1 s
  EXPECT_GT(d.ball.p_world().x(), 0.19);       // and it kept its sideways speed
}

TEST(BallEnvironment, RefusesASpringStifferThanTheSheet) {
  VirtualSheet sheet;
  BallEnvironmentOptions o;
  o.sheet_contact.stiffness_n_per_m = 1e5;
  EXPECT_THROW(BallEnvironment(sheet, o), Error);
}

}  // namespace
}  // namespace hapsim
