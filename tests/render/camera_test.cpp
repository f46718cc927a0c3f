// OrbitCamera: projections and mouse helpers checked against geometric facts (the target is at
// the viewport centre, a full turn is the identity, panned points follow the cursor, …).
#include "hapsim/render/camera.h"

#include "hapsim/core/error.h"
#include "hapsim/render/snapshot_writer.h"

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

namespace hapsim {
namespace {

constexpr int kW = 640;
constexpr int kH = 480;

OrbitCamera make_camera() {
  OrbitCamera cam;
  cam.target_world = Vec3(0.1, -0.2, 0.3);
  cam.yaw_rad = 0.7;
  cam.pitch_rad = 0.4;
  cam.distance_m = 0.8;
  cam.fov_y_rad = 0.6;
  return cam;
}

TEST(OrbitCamera, TargetProjectsToViewportCentre) {
  const OrbitCamera cam = make_camera();
  const Vec3 p = cam.project(cam.target_world, kW, kH);
  EXPECT_NEAR(p.x(), kW / 2.0, 1e-9);
  EXPECT_NEAR(p.y(), kH / 2.0, 1e-9);
  EXPECT_GT(p.z(), 0.0);
  EXPECT_LT(p.z(), 1.0);
  EXPECT_NEAR((cam.eye_world() - cam.target_world).norm(), cam.distance_m, 1e-12);
}

TEST(OrbitCamera, ZIsUpOnScreenAndRightHanded) {
  OrbitCamera cam;  // yaw 0: the eye is on +X looking towards −X
  cam.pitch_rad = 0.0;
  const Vec3 above = cam.project(Vec3(0, 0, 0.1), kW, kH);
  const Vec3 plus_y = cam.project(Vec3(0, 0.1, 0), kW, kH);
  EXPECT_LT(above.y(), kH / 2.0);   // up in the world is up on screen (smaller y)
  EXPECT_GT(plus_y.x(), kW / 2.0);  // looking along −X with Z up, +Y is to the right
}

TEST(OrbitCamera, FullTurnOfYawReturnsTheEye) {
  OrbitCamera cam = make_camera();
  const Vec3 eye0 = cam.eye_world();
  const double rad_per_px = 0.005;
  const double full_turn_px = 2.0 * std::numbers::pi / rad_per_px;
  cam.rotate(full_turn_px / 3.0, 0.0, rad_per_px);
  EXPECT_GT((cam.eye_world() - eye0).norm(), 0.5 * cam.distance_m);  // it did move
  cam.rotate(2.0 * full_turn_px / 3.0, 0.0, rad_per_px);
  EXPECT_LT((cam.eye_world() - eye0).norm(), 1e-9);
}

TEST(OrbitCamera, DragRightMovesTheEyeLeftAndPitchIsClamped) {
  OrbitCamera cam = make_camera();
  const Vec3 eye0 = cam.eye_world();
  const Vec3 right0 = cam.right_world();
  cam.rotate(10.0, 0.0);
  EXPECT_LT((cam.eye_world() - eye0).dot(right0), 0.0);
  cam.rotate(0.0, 1e6);
  EXPECT_LE(cam.pitch_rad, OrbitCamera::kMaxPitch);
  EXPECT_FALSE(cam.view_matrix().hasNaN());
}

TEST(OrbitCamera, PanKeepsThePointUnderTheCursor) {
  OrbitCamera cam = make_camera();
  // A point off-centre on the plane through the target facing the camera.
  const Vec3 p_world = cam.target_world + 0.05 * cam.right_world() - 0.03 * cam.up_world();
  const Vec3 before = cam.project(p_world, kW, kH);
  const double dx = 37.0;
  const double dy = -21.0;
  cam.pan(dx, dy, kH);
  const Vec3 after = cam.project(p_world, kW, kH);
  EXPECT_NEAR(after.x() - before.x(), dx, 1e-6);
  EXPECT_NEAR(after.y() - before.y(), dy, 1e-6);
}

TEST(OrbitCamera, ZoomMultipliesTheDistance) {
  OrbitCamera cam = make_camera();
  const double d0 = cam.distance_m;
  cam.zoom(3.0, 1.25);
  EXPECT_NEAR(cam.distance_m, d0 / std::pow(1.25, 3.0), 1e-12);
  cam.zoom(-3.0, 1.25);
  EXPECT_NEAR(cam.distance_m, d0, 1e-12);
  const Vec3 target = cam.target_world;
  cam.zoom(1.0);
  EXPECT_TRUE(cam.target_world.isApprox(target));  // zoom moves the eye, not the target
}

TEST(OrbitCamera, FrameFitsAllBoxCorners) {
  for (const double aspect : {0.5, 1.0, 16.0 / 9.0}) {
    const int w = static_cast<int>(480 * aspect);
    const int h = 480;
    OrbitCamera cam = make_camera();
    cam.distance_m = 100.0;  // far off first, so frame() must move in
    const Box3 box(Vec3(1.0, 2.0, -0.5), Vec3(1.3, 2.8, 0.1));
    cam.frame(box, static_cast<double>(w) / h);
    EXPECT_TRUE(cam.target_world.isApprox(box.center()));
    double min_x = kInf, max_x = -kInf;
    for (int i = 0; i < 8; ++i) {
      const Vec3 corner = box.corner(static_cast<Box3::CornerType>(i));
      const Vec3 p = cam.project(corner, w, h);
      EXPECT_GT(p.x(), 0.0) << "aspect " << aspect << " corner " << i;
      EXPECT_LT(p.x(), w) << "aspect " << aspect << " corner " << i;
      EXPECT_GT(p.y(), 0.0) << "aspect " << aspect << " corner " << i;
      EXPECT_LT(p.y(), h) << "aspect " << aspect << " corner " << i;
      EXPECT_GT(p.z(), 0.0);
      EXPECT_LT(p.z(), 1.0);
      min_x = std::min(min_x, p.x());
      max_x = std::max(max_x, p.x());
    }
    // …and does not leave it tiny: the box spans a good part of the viewport.
    EXPECT_GT(max_x - min_x, 0.2 * std::min(w, h));
  }
}

TEST(OrbitCamera, UnprojectInvertsProjectAndRaysPassThroughPixels) {
  const OrbitCamera cam = make_camera();
  const Vec3 p_world(0.15, -0.1, 0.35);
  const Vec3 pix = cam.project(p_world, kW, kH);
  EXPECT_TRUE(cam.unproject(pix, kW, kH).isApprox(p_world, 1e-6));

  const Ray3 ray = cam.ray_through(pix.x(), pix.y(), kW, kH);
  EXPECT_TRUE(ray.origin_world.isApprox(cam.eye_world()));
  EXPECT_NEAR(ray.direction_world.norm(), 1.0, 1e-12);
  const Vec3 to_p = p_world - ray.origin_world;
  EXPECT_LT((to_p - to_p.dot(ray.direction_world) * ray.direction_world).norm(), 1e-6);

  const Ray3 centre = cam.ray_through(kW / 2.0, kH / 2.0, kW, kH);
  EXPECT_TRUE(centre.direction_world.isApprox(cam.forward_world(), 1e-9));
}

TEST(OrbitCamera, PointsBehindTheEyeDoNotProject) {
  const OrbitCamera cam = make_camera();
  const Vec3 behind = cam.eye_world() - cam.forward_world();
  EXPECT_FALSE(std::isfinite(cam.project(behind, kW, kH).x()));
}

TEST(OrbitCamera, LookingAtPutsTheEyeAndTargetWhereAsked) {
  const Vec3 eye(-0.25, 0.3, 0.12);
  const Vec3 target(0.0, 0.06, 0.02);
  const OrbitCamera c = OrbitCamera::looking_at(eye, target, 0.7);
  EXPECT_LT((c.eye_world() - eye).norm(), 1e-12);
  EXPECT_LT((c.target_world - target).norm(), 1e-12);
  EXPECT_DOUBLE_EQ(c.fov_y_rad, 0.7);
  // The target projects to the viewport's centre.
  const Vec3 px = c.project(target, 320, 180);
  EXPECT_NEAR(px.x(), 160.0, 1e-6);
  EXPECT_NEAR(px.y(), 90.0, 1e-6);
}

TEST(OrbitCamera, CameraSpecParsesSevenNumbersAndRefusesTheRest) {
  const OrbitCamera c = parse_camera_spec("1,2,3,0.5,0.5,0,30");
  EXPECT_LT((c.eye_world() - Vec3(1.0, 2.0, 3.0)).norm(), 1e-12);
  EXPECT_NEAR(c.fov_y_rad, 30.0 * std::numbers::pi / 180.0, 1e-15);
  for (const char* bad :
       {"", "1,2,3", "1,2,3,4,5,6,7,8", "1,2,3,4,5,6,0.5", "1,2,3,1,2,3,40", "a,2,3,4,5,6,40",
        "1,2,3,4,5,6,nan", "1,,3,4,5,6,40", "1,2,3,4,5,6,40x"}) {
    EXPECT_THROW((void)parse_camera_spec(bad), Error) << bad;
  }
}

}  // namespace
}  // namespace hapsim
