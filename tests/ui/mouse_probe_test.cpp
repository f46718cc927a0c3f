// The viewer's mouse probe against the camera's own projection: a drag moves the probe's image
// by exactly the cursor's motion, the wheel moves it along the view direction by the step, it
// never leaves its workspace, and finger keys curl and release at the set rate.
#include "hapsim/ui/mouse_probe.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>

namespace hapsim {
namespace {

OrbitCamera test_camera() {
  OrbitCamera c;
  c.target_world = Vec3(0.0, 0.0, 0.1);
  c.yaw_rad = 1.95;
  c.pitch_rad = 0.3;
  c.distance_m = 0.6;
  return c;
}

TEST(MouseProbe, DragKeepsTheProbeUnderTheCursor) {
  const OrbitCamera camera = test_camera();
  const int w = 640;
  const int h = 720;
  MouseProbe probe(Vec3(0.02, 0.08, 0.12));
  const Vec3 before = camera.project(probe.p_world(), w, h);
  probe.drag(37.0, -21.0, camera, h);
  const Vec3 after = camera.project(probe.p_world(), w, h);
  EXPECT_NEAR(after.x() - before.x(), 37.0, 1e-6);
  EXPECT_NEAR(after.y() - before.y(), -21.0, 1e-6);
  // In the view plane: its distance along the view direction is unchanged.
  const double depth_before =
      (Vec3(0.02, 0.08, 0.12) - camera.eye_world()).dot(camera.forward_world());
  const double depth_after = (probe.p_world() - camera.eye_world()).dot(camera.forward_world());
  EXPECT_NEAR(depth_after, depth_before, 1e-12);
}

TEST(MouseProbe, WheelMovesAlongTheViewDirection) {
  const OrbitCamera camera = test_camera();
  MouseProbeOptions o;
  o.depth_step_m = 0.002;
  const Vec3 start(0.0, 0.1, 0.1);
  MouseProbe probe(start, o);
  probe.wheel(5.0, camera);
  const Vec3 moved = probe.p_world() - start;
  EXPECT_NEAR(moved.norm(), 0.010, 1e-12);
  EXPECT_NEAR(moved.normalized().dot(camera.forward_world()), 1.0, 1e-12);  // into the scene
  probe.wheel(-5.0, camera);
  EXPECT_NEAR((probe.p_world() - start).norm(), 0.0, 1e-12);
  // The image does not move (straight away from the eye would; along forward it shifts only
  // off-centre, and the target is on the axis) — check at the target itself.
  MouseProbe centred(camera.target_world, o);
  const Vec3 px = camera.project(centred.p_world(), 640, 720);
  centred.wheel(3.0, camera);
  const Vec3 px2 = camera.project(centred.p_world(), 640, 720);
  EXPECT_NEAR(px2.x(), px.x(), 1e-6);
  EXPECT_NEAR(px2.y(), px.y(), 1e-6);
  EXPECT_GT(px2.z(), px.z());  // deeper
}

TEST(MouseProbe, StaysInItsWorkspaceAndIgnoresNonFiniteInput) {
  MouseProbeOptions o;
  o.workspace_world = Box3(Vec3::Constant(-0.1), Vec3::Constant(0.1));
  MouseProbe probe(Vec3::Zero(), o);
  const OrbitCamera camera = test_camera();
  probe.wheel(1e6, camera);
  EXPECT_TRUE(o.workspace_world.contains(probe.p_world()));
  const Vec3 held = probe.p_world();
  probe.drag(std::numeric_limits<double>::quiet_NaN(), 3.0, camera, 720);
  probe.wheel(std::numeric_limits<double>::infinity(), camera);
  probe.place(Vec3(std::nan(""), 0, 0));
  EXPECT_EQ(probe.p_world(), held);
  EXPECT_TRUE(probe.input().p_world.allFinite());
}

TEST(MouseProbe, FingerKeysCurlAndReleaseAtTheirRate) {
  MouseProbeOptions o;
  o.finger_rate_rad_per_s = 2.0;
  o.finger_max_rad = 1.4;
  MouseProbe probe(Vec3::Zero(), o);
  std::array<bool, kMaxFingers> held{};
  held[1] = true;  // the index finger
  probe.update_fingers(held, 0.1);
  EXPECT_NEAR(probe.finger_rad()[1], 0.2, 1e-12);
  EXPECT_EQ(probe.finger_rad()[0], 0.0);
  for (int i = 0; i < 20; ++i) {
    probe.update_fingers(held, 0.1);
  }
  EXPECT_NEAR(probe.finger_rad()[1], 1.4, 1e-12);  // capped
  const DeviceInput in = probe.input();
  EXPECT_EQ(in.joint_count, 3 * kMaxFingers);
  EXPECT_NEAR(in.joint_rad[3 * 1 + 2], 1.4, 1e-12);        // PIP
  EXPECT_NEAR(in.joint_rad[3 * 1 + 1], 0.6 * 1.4, 1e-12);  // MCP flexion
  held[1] = false;
  for (int i = 0; i < 5; ++i) {
    probe.update_fingers(held, 0.1);
  }
  EXPECT_NEAR(probe.finger_rad()[1], 0.4, 1e-12);
  // One long frame (a hitch) counts as at most 0.1 s: a finger never snaps open.
  probe.update_fingers(held, 5.0);
  EXPECT_NEAR(probe.finger_rad()[1], 0.2, 1e-12);
  probe.set_grasp_closed(true);
  EXPECT_EQ(probe.input().buttons & 1U, 1U);
}

}  // namespace
}  // namespace hapsim
