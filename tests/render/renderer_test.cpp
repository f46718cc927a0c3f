// Renderer: pictures checked against geometry and the lighting equation computed here, not
// against stored images — coverage of a sphere vs its analytic disc, Lambert brightness at known
// pixels, per-vertex (Gouraud) interpolation, shadow marks where the floor point projects.
#include "hapsim/render/renderer.h"

#include "hapsim/geometry/mesh_validation.h"
#include "hapsim/geometry/procedural.h"
#include "hapsim/render/image_compare.h"
#include "render/gl_test_context.h"

#define GL_GLEXT_PROTOTYPES 1
#include <GL/glcorearb.h>

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <numbers>
#include <optional>

namespace hapsim {
namespace {

using test::pixel_at;

constexpr int kW = 320;
constexpr int kH = 240;

// One context and renderer for the whole suite (creating llvmpipe contexts is not free).
class RendererTest : public ::testing::Test {
 protected:
  static void SetUpTestSuite() { gl_.open(kW, kH); }
  static void TearDownTestSuite() { gl_.close(); }
  void SetUp() override {
    if (!gl_.context) {
      GTEST_SKIP() << "no offscreen GL context: " << gl_.why_not;
    }
  }

  // A scene on black with the floor off, and a camera on +X looking at the origin.
  static RenderScene plain_scene() {
    RenderScene scene;
    scene.floor.visible = false;
    scene.style.background = Vec3f::Zero();
    return scene;
  }
  static OrbitCamera side_camera() {
    OrbitCamera cam;
    cam.yaw_rad = 0.0;
    cam.pitch_rad = 0.0;
    cam.distance_m = 5.0;
    cam.fov_y_rad = 0.7;
    return cam;
  }

  static std::vector<std::uint8_t> render(const RenderScene& scene, const OrbitCamera& cam) {
    gl_.renderer->draw(scene, cam, kW, kH);
    EXPECT_EQ(glGetError(), static_cast<GLenum>(GL_NO_ERROR)) << "after draw";
    return gl_.context->read_rgba();
  }

  // Pixels where any colour channel exceeds `level`.
  static int count_above(const std::vector<std::uint8_t>& rgba, int level) {
    int n = 0;
    for (std::size_t i = 0; i < rgba.size(); i += 4) {
      n += std::max({rgba[i], rgba[i + 1], rgba[i + 2]}) > level ? 1 : 0;
    }
    return n;
  }

  static test::SharedGl gl_;
};

test::SharedGl RendererTest::gl_;

// Where a camera ray through a pixel centre first meets the sphere |p − c| = r, if it does.
std::optional<Vec3> hit_sphere(const Ray3& ray, const Vec3& c, double r) {
  const Vec3 oc = ray.origin_world - c;
  const double b = oc.dot(ray.direction_world);
  const double disc = b * b - (oc.squaredNorm() - r * r);
  if (disc < 0.0) {
    return std::nullopt;
  }
  return ray.origin_world + (-b - std::sqrt(disc)) * ray.direction_world;
}

TEST_F(RendererTest, FilledSphereCoversItsAnalyticDisc) {
  RenderScene scene = plain_scene();
  scene.lighting.lights.clear();  // flat white: every covered pixel is 255, edges are coverage
  scene.lighting.ambient = Vec3f::Ones();
  scene.add_mesh(make_uv_sphere(1.0, 96, 48), Vec3f::Ones());
  const OrbitCamera cam = side_camera();
  const auto rgba = render(scene, cam);

  // A sphere of radius r at distance D subtends a cone of half-angle asin(r/D); centred on the
  // axis it projects to a circle of radius tan(asin(r/D)) / tan(fov/2) · (height/2) pixels.
  const double alpha = std::asin(1.0 / cam.distance_m);
  const double r_px = std::tan(alpha) / std::tan(0.5 * cam.fov_y_rad) * (0.5 * kH);
  const double expected = std::numbers::pi * r_px * r_px;
  const int covered = count_above(rgba, 127);
  EXPECT_NEAR(covered, expected, 0.03 * expected) << "r_px " << r_px;
  // Centred: the centre pixel is covered, a pixel just outside the radius is not.
  EXPECT_EQ(pixel_at(rgba, kW, kW / 2, kH / 2).r, 255);
  EXPECT_EQ(pixel_at(rgba, kW, kW / 2 + static_cast<int>(r_px + 3), kH / 2).r, 0);
}

TEST_F(RendererTest, DisplayModesCoverPointsLessThanLinesLessThanFaces) {
  RenderScene scene = plain_scene();
  scene.add_mesh(make_uv_sphere(1.0, 24, 12), Vec3f(0.9f, 0.9f, 0.9f));
  scene.style.point_size_px = 2.0f;
  const OrbitCamera cam = side_camera();
  std::array<int, 3> covered{};
  const std::array modes = {DisplayMode::kPoints, DisplayMode::kLines, DisplayMode::kFaces};
  for (std::size_t i = 0; i < modes.size(); ++i) {
    scene.style.display_mode = modes[i];
    covered[i] = count_above(render(scene, cam), 10);
  }
  EXPECT_GT(covered[0], 0);
  EXPECT_LT(covered[0], covered[1]);
  EXPECT_LT(covered[1], covered[2] / 2);  // wires: much less than the filled disc
}

TEST_F(RendererTest, LambertBrightnessFollowsTheKeyLight) {
  RenderScene scene = plain_scene();
  const float ambient = 0.1f;
  const float key = 0.8f;
  scene.lighting.ambient = Vec3f::Constant(ambient);
  scene.lighting.specular = 0.0f;
  // World +Y, which is to the right on screen for a camera on +X.
  scene.lighting.lights = {{Vec3::UnitY(), Vec3f::Constant(key), LightFrame::kWorld}};
  scene.add_mesh(make_uv_sphere(1.0, 96, 48), Vec3f::Ones());
  const OrbitCamera cam = side_camera();
  const auto rgba = render(scene, cam);

  const int right = pixel_at(rgba, kW, kW / 2 + 40, kH / 2).r;
  const int left = pixel_at(rgba, kW, kW / 2 - 40, kH / 2).r;
  EXPECT_GT(right, left + 60);
  // Quantitatively: ambient + key·max(n·l, 0) at the surface point seen through each pixel.
  for (const int x : {kW / 2 - 40, kW / 2 - 15, kW / 2, kW / 2 + 15, kW / 2 + 30, kW / 2 + 40}) {
    for (const int y : {kH / 2 - 20, kH / 2, kH / 2 + 25}) {
      const auto hit = hit_sphere(cam.ray_through(x + 0.5, y + 0.5, kW, kH), Vec3::Zero(), 1.0);
      ASSERT_TRUE(hit.has_value()) << x << "," << y;
      const double n_dot_l = std::max(hit->normalized().y(), 0.0);
      const double expected = 255.0 * (double{ambient} + double{key} * n_dot_l);
      EXPECT_NEAR(pixel_at(rgba, kW, x, y).r, expected, 6.0) << "pixel " << x << "," << y;
    }
  }
}

TEST_F(RendererTest, LightingIsPerVertexGouraud) {
  // A 2×2-node square facing the camera, a light straight from the viewer and a tight highlight:
  // per-fragment shading would put the highlight in the centre; per-vertex shading computes it
  // only at the four corners (where it is ~0) and interpolates, so the centre stays diffuse.
  RenderScene scene = plain_scene();
  scene.lighting.ambient = Vec3f::Zero();
  scene.lighting.specular = 1.0f;
  scene.lighting.shininess = 200.0f;
  scene.lighting.lights = {{Vec3::UnitZ(), Vec3f::Constant(0.5f), LightFrame::kCamera}};
  TriangleMesh square = make_sheet(2, 1.0);  // z = 0, normal +z
  OrbitCamera cam;
  cam.pitch_rad = OrbitCamera::kMaxPitch;  // looking (almost) straight down at it
  cam.distance_m = 1.2;
  scene.add_mesh(square, Vec3f::Ones());
  const auto rgba = render(scene, cam);
  const int centre = pixel_at(rgba, kW, kW / 2, kH / 2).r;
  // Diffuse alone: 0.5 · n·l with n·l ≈ cos(90° − pitch) ≈ 1 → ~127. A per-fragment highlight
  // would add 0.5·255 on top.
  EXPECT_NEAR(centre, 127.0, 6.0);
}

TEST_F(RendererTest, ShadowMarkLiesOnTheFloorUnderThePoint) {
  RenderScene scene = plain_scene();
  scene.floor.visible = true;
  scene.floor.half_extent_m = 3.0;
  scene.floor.colour_a = scene.floor.colour_b = Vec3f::Constant(0.7f);  // one floor colour
  const Vec3 tool_world(0.3, -0.2, 0.5);
  ShadowMark mark;
  mark.point_world = tool_world;
  mark.arm_m = 0.06;
  mark.width_m = 0.015;
  mark.colour = Vec3f(0.9f, 0.1f, 0.1f);
  scene.shadow_marks.push_back(mark);
  OrbitCamera cam;
  cam.yaw_rad = 0.4;
  cam.pitch_rad = 0.8;
  cam.distance_m = 2.5;
  const auto rgba = render(scene, cam);

  const Vec3 under = cam.project(Vec3(tool_world.x(), tool_world.y(), 0.0), kW, kH);
  const auto at_mark = pixel_at(rgba, kW, static_cast<int>(under.x()), static_cast<int>(under.y()));
  EXPECT_NEAR(at_mark.r, 0.9 * 255, 3);
  EXPECT_NEAR(at_mark.g, 0.1 * 255, 3);
  // Off the mark (along +X, between its diagonal arms, beyond their reach): plain floor.
  const Vec3 beside = cam.project(Vec3(tool_world.x() + 0.1, tool_world.y(), 0.0), kW, kH);
  const auto at_floor =
      pixel_at(rgba, kW, static_cast<int>(beside.x()), static_cast<int>(beside.y()));
  EXPECT_NEAR(at_floor.r, 0.7 * 255, 2);
  EXPECT_NEAR(at_floor.g, 0.7 * 255, 2);
  // And not where the point itself projects (0.5 m above the floor).
  const Vec3 tool_px = cam.project(tool_world, kW, kH);
  EXPECT_GT(std::abs(tool_px.y() - under.y()), 20.0);
  const auto at_tool =
      pixel_at(rgba, kW, static_cast<int>(tool_px.x()), static_cast<int>(tool_px.y()));
  EXPECT_NE(at_tool.g, at_mark.g);
}

TEST_F(RendererTest, HiddenMeshDrawsNothing) {
  RenderScene scene = plain_scene();
  scene.style.background = Vec3f(0.2f, 0.3f, 0.4f);
  const OrbitCamera cam = side_camera();
  const auto empty = render(scene, cam);
  const MeshId id = scene.add_mesh(make_uv_sphere(1.0, 32, 16), Vec3f::Ones());
  const auto shown = render(scene, cam);
  scene.mesh(id).visible = false;
  const auto hidden = render(scene, cam);
  EXPECT_GT(compare_images(empty, shown, kW, kH).differing_fraction, 0.05);
  const ImageDiff d = compare_images(empty, hidden, kW, kH, 0);
  EXPECT_EQ(d.max_abs_diff, 0) << d.describe();
}

// Levels of detail by screen size: a detailed sphere close up is drawn in full; far away a
// coarser level is drawn, and its picture is the full mesh's within a few edge pixels (no hole,
// no shift); with level_of_detail off, always in full.
TEST_F(RendererTest, FarMeshesDrawACoarserLevelThatLooksTheSame) {
  RenderScene scene = plain_scene();
  scene.add_mesh(make_bumpy_sphere(20000, 0.05), Vec3f(0.8f, 0.7f, 0.6f));
  ASSERT_FALSE(scene.mesh(0).lod_levels().empty());
  scene.style.level_of_detail = true;
  OrbitCamera cam = side_camera();
  cam.distance_m = 0.08;  // close up: the sphere overfills the view
  render(scene, cam);
  const RenderStats near = gl_.renderer->last_frame_stats();
  EXPECT_EQ(near.triangles_drawn, near.triangles_full);
  cam.distance_m = 2.0;  // a few dozen pixels across
  // Hysteresis: the level settles over a couple of frames.
  render(scene, cam);
  const auto coarse = render(scene, cam);
  const RenderStats far = gl_.renderer->last_frame_stats();
  EXPECT_LT(far.triangles_drawn, far.triangles_full / 2);
  EXPECT_EQ(far.meshes_coarser, 1u);
  scene.style.level_of_detail = false;
  const auto full = render(scene, cam);
  EXPECT_EQ(gl_.renderer->last_frame_stats().triangles_drawn, far.triangles_full);
  const ImageDiff d = compare_images(full, coarse, kW, kH);
  EXPECT_LT(d.differing_fraction, 0.01) << d.describe();
}

TEST_F(RendererTest, UpdatedPositionsChangeOnlyTheDentedRegion) {
  RenderScene scene = plain_scene();
  const TriangleMesh sphere = make_uv_sphere(1.0, 64, 32);
  const MeshId id = scene.add_mesh(sphere, Vec3f(0.8f, 0.7f, 0.6f));
  OrbitCamera cam = side_camera();
  cam.pitch_rad = 0.3;  // sees the top cap
  const auto before = render(scene, cam);

  // Dent a patch on the top: vertices above z = 0.8 move 15% towards the centre.
  std::vector<Vec3> dented = sphere.vertices;
  for (Vec3& v : dented) {
    if (v.z() > 0.8) {
      v *= 0.85;
    }
  }
  scene.update_positions(id, dented);
  const auto after = render(scene, cam);

  // The region that may change: where the patch and its one-ring neighbours (their normals
  // change) project, before or after the dent, plus a pixel of rasterisation slack.
  double x0 = kInf, x1 = -kInf, y0 = kInf, y1 = -kInf;
  for (std::size_t i = 0; i < sphere.vertices.size(); ++i) {
    if (sphere.vertices[i].z() > 0.7) {
      for (const Vec3& p : {sphere.vertices[i], dented[i]}) {
        const Vec3 px = cam.project(p, kW, kH);
        x0 = std::min(x0, px.x()), x1 = std::max(x1, px.x());
        y0 = std::min(y0, px.y()), y1 = std::max(y1, px.y());
      }
    }
  }
  int changed_inside = 0;
  int changed_outside = 0;
  for (int y = 0; y < kH; ++y) {
    for (int x = 0; x < kW; ++x) {
      const auto a = pixel_at(before, kW, x, y);
      const auto b = pixel_at(after, kW, x, y);
      const int d = std::max({std::abs(a.r - b.r), std::abs(a.g - b.g), std::abs(a.b - b.b)});
      if (d <= 2) {
        continue;
      }
      const bool inside = x >= x0 - 2 && x <= x1 + 2 && y >= y0 - 2 && y <= y1 + 2;
      ++(inside ? changed_inside : changed_outside);
    }
  }
  EXPECT_GT(changed_inside, 100);
  EXPECT_EQ(changed_outside, 0);
}

TEST_F(RendererTest, PaletteModeGivesMeshesDistinctColours) {
  RenderScene scene = plain_scene();
  scene.lighting.lights.clear();
  scene.lighting.ambient = Vec3f::Ones();  // unlit: pixels show the base colour
  const TriangleMesh ball = make_uv_sphere(0.5, 32, 16);
  scene.add_mesh(ball, Vec3f::Ones(), Iso3(Eigen::Translation3d(0, -0.8, 0)));
  scene.add_mesh(ball, Vec3f::Ones(), Iso3(Eigen::Translation3d(0, 0.8, 0)));
  scene.style.colour_mode = ColourMode::kPalette;
  const OrbitCamera cam = side_camera();
  const auto rgba = render(scene, cam);
  for (int i = 0; i < 2; ++i) {
    const Vec3 px = cam.project(Vec3(0, i == 0 ? -0.8 : 0.8, 0), kW, kH);
    const auto p = pixel_at(rgba, kW, static_cast<int>(px.x()), static_cast<int>(px.y()));
    const Vec3f expected = 255.0f * palette_colour(i);
    EXPECT_NEAR(p.r, expected.x(), 2.0) << "mesh " << i;
    EXPECT_NEAR(p.g, expected.y(), 2.0) << "mesh " << i;
    EXPECT_NEAR(p.b, expected.z(), 2.0) << "mesh " << i;
  }
}

TEST_F(RendererTest, VertexColoursAreInterpolated) {
  RenderScene scene = plain_scene();
  scene.lighting.lights.clear();
  scene.lighting.ambient = Vec3f::Ones();
  const TriangleMesh ball = make_uv_sphere(1.0, 48, 24);
  const MeshId id = scene.add_mesh(ball, Vec3f::Ones());
  // Two groups: the +Y half red, the −Y half blue.
  std::vector<Vec3f> colours;
  for (const Vec3& v : ball.vertices) {
    colours.push_back(v.y() >= 0 ? Vec3f(1, 0, 0) : Vec3f(0, 0, 1));
  }
  scene.set_vertex_colours(id, colours);
  const OrbitCamera cam = side_camera();
  const auto rgba = render(scene, cam);
  const auto right = pixel_at(rgba, kW, kW / 2 + 30, kH / 2);  // +Y side
  const auto left = pixel_at(rgba, kW, kW / 2 - 30, kH / 2);
  EXPECT_GT(right.r, 250);
  EXPECT_LT(right.b, 5);
  EXPECT_GT(left.b, 250);
  EXPECT_LT(left.r, 5);
  scene.style.colour_mode = ColourMode::kMeshColour;  // per-mesh colour overrides
  const auto white = pixel_at(render(scene, cam), kW, kW / 2 + 30, kH / 2);
  EXPECT_GT(white.b, 250);
}

TEST_F(RendererTest, SpheresAndSegmentsAppearWhereTheyProject) {
  RenderScene scene = plain_scene();
  scene.lighting.lights.clear();
  scene.lighting.ambient = Vec3f::Ones();
  scene.spheres.push_back({Vec3(0, -0.5, 0.2), 0.2, Vec3f(0, 1, 0), false});
  scene.segments.push_back({Vec3(0, 0.3, -0.6), Vec3(0, 0.3, 0.6), Vec3f(1, 0, 1)});
  scene.style.line_width_px = 3.0f;
  const OrbitCamera cam = side_camera();
  const auto rgba = render(scene, cam);
  const Vec3 s = cam.project(Vec3(0, -0.5, 0.2), kW, kH);
  EXPECT_GT(pixel_at(rgba, kW, static_cast<int>(s.x()), static_cast<int>(s.y())).g, 250);
  const Vec3 m = cam.project(Vec3(0, 0.3, 0.0), kW, kH);
  const auto on_line = pixel_at(rgba, kW, static_cast<int>(m.x()), static_cast<int>(m.y()));
  EXPECT_GT(on_line.r, 250);
  EXPECT_GT(on_line.b, 250);
  const Vec3 bounds_centre = scene.bounds_world().center();
  EXPECT_TRUE(bounds_centre.isApprox(Vec3(0, -0.5, 0.2)));  // segments are not in bounds_world
}

TEST(Palette, FirstColoursAreWellSeparated) {
  for (int i = 0; i < 16; ++i) {
    for (int j = i + 1; j < 16; ++j) {
      EXPECT_GT((palette_colour(i) - palette_colour(j)).norm(), 0.15f) << i << " vs " << j;
    }
    EXPECT_GE(palette_colour(i).minCoeff(), 0.0f);
    EXPECT_LE(palette_colour(i).maxCoeff(), 1.0f);
  }
}

TEST(RenderScene, UpdatePositionsChecksTheVertexCount) {
  RenderScene scene;
  const MeshId id = scene.add_mesh(make_box(Vec3::Ones()), Vec3f::Ones());
  const std::vector<Vec3> too_few(3, Vec3::Zero());
  EXPECT_THROW(scene.update_positions(id, too_few), Error);
  EXPECT_THROW(scene.update_positions(id + 1, too_few), Error);
  const auto stamp = scene.mesh(id).vertex_stamp();
  std::vector<Vec3> moved = scene.mesh(id).geometry().vertices;
  scene.update_positions(id, moved);
  EXPECT_NE(scene.mesh(id).vertex_stamp(), stamp);
}

// Only a closed, outward surface has its back faces culled: an open one (a cut mesh, a sheet)
// and an inside-out one show their back faces, which culling would hide.
TEST(RenderScene, OnlyClosedOutwardMeshesAreMarkedClosed) {
  RenderScene scene;
  const TriangleMesh box = make_box(Vec3::Ones());
  EXPECT_TRUE(scene.mesh(scene.add_mesh(box, Vec3f::Ones())).closed());
  EXPECT_TRUE(scene.mesh(scene.add_mesh(make_uv_sphere(1.0, 16, 8), Vec3f::Ones())).closed());
  TriangleMesh open = box;
  open.triangles.pop_back();
  open.vertex_normals.clear();
  EXPECT_FALSE(scene.mesh(scene.add_mesh(open, Vec3f::Ones())).closed());
  TriangleMesh inside_out = box;
  flip_orientation(inside_out);
  EXPECT_FALSE(scene.mesh(scene.add_mesh(inside_out, Vec3f::Ones())).closed());
}

}  // namespace
}  // namespace hapsim
