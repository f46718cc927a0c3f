// WorldScene drawing a scene file's Gaussian sheet (hand_ball_sheet.json: a 0.2 m 32x32 sheet 5 cm
// above a table top, its body at (0.12, 0, 0.05)) and a rig's (teleop.json): the drawn sheet mesh's
// world-space vertices (mesh pose × vertex) are the world's own sheet (the body pose × the rest
// grid), from the world, from a snapshot, and at construction; and drawn, the sheet's pixels fill
// exactly the quad its world corners project to, with the table neither in front of it nor under
// it (from the side, there is a gap between the table top and the sheet).
#include "hapsim/render/world_scene.h"

#include "hapsim/geometry/procedural.h"
#include "hapsim/render/renderer.h"
#include "hapsim/render/snapshot_writer.h"
#include "hapsim/rig/rig_controller.h"
#include "hapsim/runtime/world_snapshot.h"
#include "hapsim/scene/run_setup.h"
#include "hapsim/scene/scene_file.h"
#include "render/gl_test_context.h"

#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <filesystem>
#include <memory>
#include <numbers>
#include <optional>

namespace hapsim {
namespace {

using test::pixel_at;

std::filesystem::path scene_path(const char* name) {
  return std::filesystem::path(HAPSIM_SOURCE_DIR) / "scenes" / name;
}

std::size_t body_named(const WorldDescription& d, const std::string& name) {
  for (std::size_t b = 0; b < d.bodies.size(); ++b) {
    if (d.bodies[b].name == name) {
      return b;
    }
  }
  ADD_FAILURE() << "no body '" << name << "'";
  return 0;
}

// A scene file assembled as `hapsim run` assembles it (make_run_setup: its world, its scripted
// device), stepped `steps` cycles by that device (`--duration 0.05` is 50).
struct SceneRun {
  explicit SceneRun(const char* name, int steps = 50)
      : setup(make_run_setup(load_scene(scene_path(name)), DeviceChoice::scene_script())),
        world(*setup.world) {
    for (int i = 0; i < steps; ++i) {
      world.step(setup.device->read(i * setup.scene.run.dt_s), setup.scene.run.dt_s);
    }
  }
  RunSetup setup;
  World& world;
};

// Every drawn vertex of the sheet (mesh pose × vertex) against the world's sheet at rest (the body
// pose × make_sheet's grid, built here, not read back from the world).
void expect_sheet_drawn_as_the_world_has_it(const WorldScene& view, const World& world,
                                            std::size_t sheet_body, double tolerance_m) {
  const BodyDescription& body = world.description().bodies[sheet_body];
  const TriangleMesh grid = make_sheet(body.sheet.nodes_per_side, body.sheet.side_m);
  const RenderMesh& mesh = view.scene().mesh(
      view.segment_mesh(world.flat_segment(BodyIndex{sheet_body}, LocalSegment{0}).index()));
  ASSERT_EQ(mesh.geometry().vertices.size(), grid.vertices.size());
  for (std::size_t k = 0; k < grid.vertices.size(); ++k) {
    const Vec3 drawn = mesh.X_world_mesh * mesh.geometry().vertices[k];
    const Vec3 world_k = body.X_world_body * grid.vertices[k];
    ASSERT_LE((drawn - world_k).norm(), tolerance_m)
        << "node " << k << " drawn at " << drawn.transpose() << ", the world's at "
        << world_k.transpose();
  }
}

TEST(WorldSceneSheet, HandBallSheetsDrawnVerticesAreTheWorldsSheet) {
  const SceneRun s("hand_ball_sheet.json");
  const World& world = s.world;
  const std::size_t sheet = body_named(world.description(), "sheet");
  ASSERT_NE(world.sheet(sheet), nullptr);
  ASSERT_LT(world.sheet(sheet)->max_depth_m(), 1e-9) << "nothing presses the sheet in 50 ms";
  // The scene file's numbers: the body at (0.12, 0, 0.05), a 0.2 m grid, corners at ±0.1 m.
  EXPECT_TRUE(world.body_pose(sheet).isApprox(Iso3(Eigen::Translation3d(0.12, 0.0, 0.05)), 0.0));
  WorldScene at_build(world);
  WorldScene from_world(world);
  from_world.update_from_world(world);
  WorldScene from_snapshot(world);
  from_snapshot.update(make_world_snapshot(world));
  for (const WorldScene* view : {&at_build, &from_world, &from_snapshot}) {
    expect_sheet_drawn_as_the_world_has_it(*view, world, sheet, 1e-7);
    const RenderMesh& mesh = view->scene().mesh(
        view->segment_mesh(world.flat_segment(BodyIndex{sheet}, LocalSegment{0}).index()));
    Box3 drawn;
    for (const Vec3& v : mesh.geometry().vertices) {
      drawn.extend(mesh.X_world_mesh * v);
    }
    EXPECT_NEAR(drawn.min().x(), 0.02, 1e-7);
    EXPECT_NEAR(drawn.max().x(), 0.22, 1e-7);
    EXPECT_NEAR(drawn.min().y(), -0.1, 1e-7);
    EXPECT_NEAR(drawn.max().y(), 0.1, 1e-7);
    EXPECT_NEAR(drawn.min().z(), 0.05, 1e-7);
    EXPECT_NEAR(drawn.max().z(), 0.05, 1e-7);
    // The table is drawn with its top at z = 0, 5 cm under the sheet.
    const std::size_t table = body_named(world.description(), "table");
    const RenderMesh& table_mesh = view->scene().mesh(
        view->segment_mesh(world.flat_segment(BodyIndex{table}, LocalSegment{0}).index()));
    Box3 table_drawn;
    for (const Vec3& v : table_mesh.geometry().vertices) {
      table_drawn.extend(table_mesh.X_world_mesh * v);
    }
    EXPECT_NEAR(table_drawn.max().z(), 0.0, 1e-12);
    EXPECT_NEAR(table_drawn.min().x(), -0.3, 1e-12);
    EXPECT_NEAR(table_drawn.max().x(), 0.3, 1e-12);
  }
}

TEST(WorldSceneSheet, TeleopSheetsDrawnVerticesAreTheWorldsSheet) {
  const SceneRun s("teleop.json");
  const World& world = s.world;
  const std::size_t sheet = rig_description(world.description())->sheet_body;
  EXPECT_TRUE(world.body_pose(sheet).isApprox(Iso3(Eigen::Translation3d(0.5, 0.25, 0.05)), 0.0));
  WorldScene at_build(world);
  WorldScene from_world(world);
  from_world.update_from_world(world);
  WorldScene from_snapshot(world);
  from_snapshot.update(make_world_snapshot(world));
  for (const WorldScene* view : {&at_build, &from_world, &from_snapshot}) {
    expect_sheet_drawn_as_the_world_has_it(*view, world, sheet, 1e-7);
  }
}

// Drawn: what `hapsim run --snapshot` shows of hand_ball_sheet.json (its camera: azimuth 1.95,
// elevation 0.75, framed on the rest bounds), and a view from the side, level with the table.
class WorldSceneSheetPicture : public ::testing::Test {
 protected:
  static constexpr int kW = 640;
  static constexpr int kH = 360;

  static void SetUpTestSuite() { gl_.open(kW, kH); }
  static void TearDownTestSuite() { gl_.close(); }
  void SetUp() override {
    if (!gl_.context) {
      GTEST_SKIP() << "no offscreen GL context: " << gl_.why_not;
    }
  }
  static std::vector<std::uint8_t> render(const RenderScene& scene, const OrbitCamera& cam) {
    gl_.renderer->draw(scene, cam, kW, kH);
    return gl_.context->read_rgba();
  }
  // The sheet's light blue (shaded), the table's brown.
  static bool blue(const test::Pixel& p) { return p.b > p.r + 40; }
  static bool brown(const test::Pixel& p) { return p.r > p.b + 40 && p.g > p.b; }

  static test::SharedGl gl_;
};

test::SharedGl WorldSceneSheetPicture::gl_;

// Signed distance (pixels) from (x, y) to the convex quad `q` (counter-clockwise or clockwise):
// negative inside.
double signed_distance_px(const std::array<Vec3, 4>& q, double x, double y) {
  double orientation = 0.0;
  for (std::size_t i = 0; i < 4; ++i) {
    const Vec3& a = q[i];
    const Vec3& b = q[(i + 1) % 4];
    orientation += (b.x() - a.x()) * (b.y() + a.y());
  }
  const double sign = orientation > 0.0 ? 1.0 : -1.0;
  double d = -kInf;
  for (std::size_t i = 0; i < 4; ++i) {
    const Vec3& a = q[i];
    const Vec3& b = q[(i + 1) % 4];
    const double ex = b.x() - a.x();
    const double ey = b.y() - a.y();
    // Outward normal of edge a→b for this orientation.
    const double nx = sign * ey;
    const double ny = -sign * ex;
    const double len = std::hypot(nx, ny);
    d = std::max(d, -((x - a.x()) * nx + (y - a.y()) * ny) / len);
  }
  return d;
}

TEST_F(WorldSceneSheetPicture, SheetFillsTheQuadItsWorldCornersProjectTo) {
  const SceneRun s("hand_ball_sheet.json");
  const World& world = s.world;
  WorldScene view(world);
  view.update_from_world(world);
  const OrbitCamera cam =
      framed_camera(view.rest_bounds_world(), static_cast<double>(kW) / kH, 1.95, 0.75);
  // The glove hand and its fingertips (purple, bluish): this is about the sheet.
  view.scene().capsules.clear();
  view.scene().spheres.clear();
  const auto image = render(view.scene(), cam);
  const Iso3& X = world.body_pose(body_named(world.description(), "sheet"));
  std::array<Vec3, 4> quad;
  const std::array<std::array<double, 2>, 4> corners = {
      {{-0.1, -0.1}, {0.1, -0.1}, {0.1, 0.1}, {-0.1, 0.1}}};
  for (std::size_t i = 0; i < 4; ++i) {
    quad[i] = cam.project(X * Vec3(corners[i][0], corners[i][1], 0.0), kW, kH);
  }
  int inside = 0;
  int inside_blue = 0;
  int outside_blue = 0;
  for (int y = 0; y < kH; ++y) {
    for (int x = 0; x < kW; ++x) {
      const double d = signed_distance_px(quad, x + 0.5, y + 0.5);
      const bool is_blue = blue(pixel_at(image, kW, x, y));
      if (d < -1.5) {
        ++inside;
        inside_blue += is_blue ? 1 : 0;
      } else if (d > 1.5) {
        outside_blue += is_blue ? 1 : 0;
      }
    }
  }
  ASSERT_GT(inside, 500);
  // Nothing (the table) hides any of it, and no blue is drawn anywhere else.
  EXPECT_EQ(inside_blue, inside);
  EXPECT_EQ(outside_blue, 0);
}

TEST_F(WorldSceneSheetPicture, FromTheSideTheSheetHoversOverTheTableTop) {
  const SceneRun s("hand_ball_sheet.json");
  const World& world = s.world;
  WorldScene view(world);
  view.update_from_world(world);
  // From −y, 0.08 rad above level, looking at the sheet's centre through a narrow lens (the sheet
  // is a band a dozen pixels high).
  OrbitCamera cam;
  cam.fov_y_rad = 0.35;
  cam.target_world = Vec3(0.12, 0.0, 0.025);
  cam.yaw_rad = -0.5 * std::numbers::pi;
  cam.pitch_rad = 0.08;
  cam.distance_m = 0.6;
  const auto image = render(view.scene(), cam);
  const auto at = [&](const Vec3& p_world) {
    const Vec3 px = cam.project(p_world, kW, kH);
    return pixel_at(image, kW, static_cast<int>(px.x()), static_cast<int>(px.y()));
  };
  for (const double x : {0.05, 0.12, 0.19}) {
    // The sheet, seen at a grazing angle, at its height.
    EXPECT_TRUE(blue(at(Vec3(x, 0.0, 0.05)))) << "x " << x;
    // Half way down to the table: the line of sight passes under the sheet's near edge and over
    // the table's far edge (neither blue nor brown).
    const test::Pixel gap = at(Vec3(x, 0.0, 0.025));
    EXPECT_FALSE(blue(gap)) << "x " << x;
    EXPECT_FALSE(brown(gap)) << "x " << x;
    // The table's front face, below its top.
    EXPECT_TRUE(brown(at(Vec3(x, -0.2, -0.01)))) << "x " << x;
  }
}

}  // namespace
}  // namespace hapsim
