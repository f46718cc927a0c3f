#include "hapsim/ui/space_mouse_camera.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>

namespace hapsim {
namespace {

OrbitCamera start_camera() {
  OrbitCamera c;
  c.target_world = Vec3(0.1, -0.2, 0.3);
  c.yaw_rad = 0.4;
  c.pitch_rad = 0.2;
  c.distance_m = 0.8;
  return c;
}

// N frames of one reading held at 60 Hz.
OrbitCamera driven(const SpaceMouseAxes& axes, int frames, const SpaceMouseCameraOptions& o = {}) {
  OrbitCamera c = start_camera();
  for (int i = 0; i < frames; ++i) {
    drive_camera(c, axes, 1.0 / 60.0, o);
  }
  return c;
}

TEST(SpaceMouseCamera, AFullTwistForOneSecondTurnsTheOrbitByTheFullRate) {
  SpaceMouseCameraOptions o;
  o.full_turn_rad_per_s = 1.5;
  SpaceMouseAxes twist;
  twist.rotation.y() = 1.0;  // counter-clockwise from above: the scene turns so, the eye the other
  const OrbitCamera c = driven(twist, 60, o);
  const OrbitCamera s = start_camera();
  EXPECT_NEAR(c.yaw_rad, s.yaw_rad - 1.5, 1e-9);
  // A pure twist changes nothing else.
  EXPECT_DOUBLE_EQ(c.pitch_rad, s.pitch_rad);
  EXPECT_DOUBLE_EQ(c.distance_m, s.distance_m);
  EXPECT_TRUE(c.target_world.isApprox(s.target_world, 1e-15));
  // The eye went round the target, at the same distance, by that angle about Z.
  const Vec3 before = s.eye_world() - s.target_world;
  const Vec3 after = c.eye_world() - c.target_world;
  const double turned = std::atan2(before.x() * after.y() - before.y() * after.x(),
                                   before.x() * after.x() + before.y() * after.y());
  EXPECT_NEAR(turned, -1.5, 1e-9);
}

TEST(SpaceMouseCamera, PastTheDeadZoneTheRateGrowsFromZeroToFull) {
  SpaceMouseCameraOptions o;
  o.dead_zone = 0.05;
  SpaceMouseAxes a;
  a.rotation.y() = 0.04;  // inside the dead zone: the puck at rest
  a.translation = Vec3(0.049, -0.03, 0.02);
  const OrbitCamera still = driven(a, 120, o);
  EXPECT_DOUBLE_EQ(still.yaw_rad, start_camera().yaw_rad);
  EXPECT_TRUE(still.target_world.isApprox(start_camera().target_world, 1e-15));
  EXPECT_DOUBLE_EQ(still.distance_m, start_camera().distance_m);
  // Half deflection: (0.5 − 0.05) / 0.95 of the full rate, over 2 s (120 frames).
  a = SpaceMouseAxes{};
  a.rotation.y() = -0.5;
  const OrbitCamera half = driven(a, 120, o);
  EXPECT_NEAR(half.yaw_rad - start_camera().yaw_rad, 2.0 * o.full_turn_rad_per_s * 0.45 / 0.95,
              1e-9);
}

TEST(SpaceMouseCamera, TiltShowsTheTopAndStopsShortOfStraightDown) {
  SpaceMouseAxes tilt;
  tilt.rotation.x() = 1.0;  // the cap's top towards the user
  OrbitCamera c = driven(tilt, 6);
  EXPECT_NEAR(c.pitch_rad, 0.2 + 1.5 * 0.1, 1e-9);
  c = driven(tilt, 600);
  EXPECT_DOUBLE_EQ(c.pitch_rad, OrbitCamera::kMaxPitch);
  tilt.rotation.x() = -1.0;
  c = driven(tilt, 600);
  EXPECT_DOUBLE_EQ(c.pitch_rad, -OrbitCamera::kMaxPitch);
}

TEST(SpaceMouseCamera, PushPansTheSceneAndPullZoomsIn) {
  SpaceMouseCameraOptions o;
  o.full_pan_distances_per_s = 0.5;
  o.full_zoom_per_s = 1.0;
  const OrbitCamera s = start_camera();
  SpaceMouseAxes push;
  push.translation.x() = 1.0;  // right: the scene moves right, the target left
  OrbitCamera c = driven(push, 60, o);
  EXPECT_TRUE((c.target_world - s.target_world).isApprox(-0.5 * 0.8 * s.right_world(), 1e-9))
      << (c.target_world - s.target_world).transpose();
  // The target was right of centre before, so a point at it now projects right of the middle.
  const Vec3 seen = c.project(s.target_world, 640, 480);
  EXPECT_GT(seen.x(), 320.0 + 10.0);
  SpaceMouseAxes lift;
  lift.translation.y() = 1.0;
  c = driven(lift, 60, o);
  EXPECT_TRUE((c.target_world - s.target_world).isApprox(-0.5 * 0.8 * s.up_world(), 1e-9));
  SpaceMouseAxes pull;
  pull.translation.z() = 1.0;  // towards the user: nearer
  c = driven(pull, 60, o);
  EXPECT_NEAR(c.distance_m, 0.8 * std::exp(-1.0), 1e-9);
  pull.translation.z() = -1.0;
  c = driven(pull, 60, o);
  EXPECT_NEAR(c.distance_m, 0.8 * std::exp(1.0), 1e-9);
}

TEST(SpaceMouseCamera, RollDoesNothingAndAStallOrNaNDoesNotFlingTheView) {
  SpaceMouseAxes roll;
  roll.rotation.z() = 1.0;
  OrbitCamera c = driven(roll, 60);
  EXPECT_DOUBLE_EQ(c.yaw_rad, start_camera().yaw_rad);
  EXPECT_DOUBLE_EQ(c.pitch_rad, start_camera().pitch_rad);
  SpaceMouseAxes twist;
  twist.rotation.y() = 1.0;
  c = start_camera();
  drive_camera(c, twist, 5.0);  // a 5 s frame counts as max_dt_s
  EXPECT_NEAR(c.yaw_rad, start_camera().yaw_rad - 1.5 * SpaceMouseCameraOptions{}.max_dt_s, 1e-12);
  twist.rotation.y() = std::numeric_limits<double>::quiet_NaN();
  twist.translation.z() = std::numeric_limits<double>::infinity();
  c = start_camera();
  drive_camera(c, twist, 1.0 / 60.0);
  EXPECT_DOUBLE_EQ(c.yaw_rad, start_camera().yaw_rad);
  EXPECT_DOUBLE_EQ(c.distance_m, start_camera().distance_m);
}

}  // namespace
}  // namespace hapsim
