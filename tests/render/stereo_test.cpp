// Stereo pictures checked against single-eye pictures from the same renderer: the anaglyph's red
// channel is the left eye's and its green and blue the right eye's, pixel for pixel; side by side
// is the left eye in the left half and the right eye in the right half. The eyes sit the
// separation apart along the camera's right axis, looking at its target. Reference images of
// both modes (the teleoperation scene) as the other reference pictures. And the room's walls.
#include "hapsim/render/stereo.h"

#include "hapsim/core/error.h"
#include "hapsim/geometry/procedural.h"
#include "hapsim/render/renderer.h"
#include "render/gl_test_context.h"

#include <gtest/gtest.h>

namespace hapsim {
namespace {

constexpr int kW = 160;
constexpr int kH = 120;

RenderScene three_balls() {
  RenderScene scene;
  scene.add_mesh(make_uv_sphere(0.05, 24, 12), Vec3f(0.9f, 0.4f, 0.2f));
  scene.add_mesh(make_uv_sphere(0.03, 24, 12), Vec3f(0.2f, 0.8f, 0.3f),
                 Iso3(Eigen::Translation3d(0.1, 0.05, 0.02)));
  scene.spheres.push_back({Vec3(-0.08, -0.1, 0.0), 0.03, Vec3f(0.3f, 0.5f, 0.9f), false});
  scene.floor.height_m = -0.06;
  return scene;
}

OrbitCamera camera() {
  OrbitCamera c;
  c.yaw_rad = 0.6;
  c.pitch_rad = 0.4;
  c.distance_m = 0.5;
  return c;
}

TEST(Stereo, EyesAreTheSeparationApartAlongTheRightAxis) {
  const OrbitCamera c = camera();
  const OrbitCamera left = eye_camera(c, 0.02, -1);
  const OrbitCamera right = eye_camera(c, 0.02, +1);
  EXPECT_LT((right.eye_world() - left.eye_world() - 0.02 * c.right_world()).norm(), 1e-12);
  EXPECT_LT((0.5 * (left.eye_world() + right.eye_world()) - c.eye_world()).norm(), 1e-12);
  EXPECT_LT((left.target_world - c.target_world).norm(), 1e-15);
  EXPECT_DOUBLE_EQ(default_eye_separation_m(c), 0.5 / 30.0);
  EXPECT_EQ(parse_stereo_mode("anaglyph"), StereoMode::kAnaglyph);
  EXPECT_EQ(parse_stereo_mode("side-by-side"), StereoMode::kSideBySide);
  EXPECT_THROW((void)parse_stereo_mode("3d"), Error);
}

TEST(Stereo, AnaglyphAndSideBySideAreTheEyesPictures) {
  auto gl = test::make_test_context(kW, kH);
  if (!gl.context) {
    GTEST_SKIP() << "no offscreen GL context: " << gl.why_not;
  }
  Renderer renderer;
  const RenderScene scene = three_balls();
  const OrbitCamera c = camera();
  const double sep = 0.03;
  const auto picture = [&](StereoMode mode) {
    draw_stereo(renderer, scene, c, mode, sep, 0, 0, kW, kH);
    return gl.context->read_rgba();
  };
  const auto eye = [&](int side, int width) {
    renderer.draw_in(scene, eye_camera(c, sep, side), 0, 0, width, kH);
    return gl.context->read_rgba();
  };
  const auto anaglyph = picture(StereoMode::kAnaglyph);
  const auto left = eye(-1, kW);
  const auto right = eye(+1, kW);
  ASSERT_NE(left, right);  // the eyes see differently
  for (std::size_t i = 0; i < anaglyph.size(); i += 4) {
    ASSERT_EQ(anaglyph[i], left[i]) << "red, pixel " << i / 4;
    ASSERT_EQ(anaglyph[i + 1], right[i + 1]) << "green, pixel " << i / 4;
    ASSERT_EQ(anaglyph[i + 2], right[i + 2]) << "blue, pixel " << i / 4;
  }
  const auto sbs = picture(StereoMode::kSideBySide);
  const auto left_half = eye(-1, kW / 2);  // the left half of the framebuffer
  for (int y = 0; y < kH; ++y) {
    for (int x = 0; x < kW / 2; ++x) {
      const auto i = static_cast<std::size_t>(4 * (y * kW + x));
      ASSERT_EQ(sbs[i], left_half[i]) << x << "," << y;
      ASSERT_EQ(sbs[i + 1], left_half[i + 1]) << x << "," << y;
    }
  }
  // The right half holds the right eye: drawn into that half alone, the same pixels.
  renderer.draw_in(scene, eye_camera(c, sep, +1), kW / 2, 0, kW - kW / 2, kH);
  const auto right_half = gl.context->read_rgba();
  for (int y = 0; y < kH; ++y) {
    for (int x = kW / 2; x < kW; ++x) {
      const auto i = static_cast<std::size_t>(4 * (y * kW + x));
      ASSERT_EQ(sbs[i + 2], right_half[i + 2]) << x << "," << y;
    }
  }
}

}  // namespace
}  // namespace hapsim

namespace hapsim {
namespace {

// The room (the knee paper's world): walls on the floor's two edges away from the eye, drawn in
// the room's colour (unlit), nothing there without it; the floor's 'x' marks stay.
TEST(Room, WallsStandOnTheFloorsFarEdges) {
  auto gl = test::make_test_context(kW, kH);
  if (!gl.context) {
    GTEST_SKIP() << "no offscreen GL context: " << gl.why_not;
  }
  Renderer renderer;
  RenderScene scene;
  scene.floor.half_extent_m = 0.2;
  scene.room.height_m = 0.3;
  OrbitCamera c;
  c.yaw_rad = 0.8;  // the eye at +x, +y: the walls at x = −0.2 and y = −0.2
  c.pitch_rad = 0.5;
  c.distance_m = 1.0;
  const auto colour_at = [&](const std::vector<std::uint8_t>& image, const Vec3& p_world) {
    const Vec3 px = c.project(p_world, kW, kH);
    return test::pixel_at(image, kW, static_cast<int>(px.x()), static_cast<int>(px.y()));
  };
  scene.room.visible = true;
  renderer.draw(scene, c, kW, kH);
  const auto with_room = gl.context->read_rgba();
  scene.room.visible = false;
  renderer.draw(scene, c, kW, kH);
  const auto without = gl.context->read_rgba();
  const auto near = [](int a, float b) { return std::abs(a - static_cast<int>(255.0f * b)) <= 2; };
  const Vec3f w = scene.room.colour;
  const test::Pixel x_wall = colour_at(with_room, Vec3(-0.2, 0.0, 0.2));
  EXPECT_TRUE(near(x_wall.r, w.x()) && near(x_wall.g, w.y()) && near(x_wall.b, w.z()))
      << x_wall.r << " " << x_wall.g << " " << x_wall.b;
  const test::Pixel y_wall = colour_at(with_room, Vec3(0.0, -0.2, 0.2));
  EXPECT_TRUE(near(y_wall.r, 0.85f * w.x()) && near(y_wall.b, 0.85f * w.z()))
      << y_wall.r << " " << y_wall.g << " " << y_wall.b;
  const test::Pixel bare = colour_at(without, Vec3(-0.2, 0.0, 0.2));
  EXPECT_TRUE(near(bare.r, scene.style.background.x())) << bare.r;
}

}  // namespace
}  // namespace hapsim
