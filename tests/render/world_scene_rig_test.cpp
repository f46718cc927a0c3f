// WorldScene drawing a teleoperation rig: what it draws checked against the world's own geometry,
// not stored images — after a scripted pick-and-place the sheet mesh holds the world's dented
// heights exactly (from the world and from a snapshot), the ball's colour appears where the
// ball's centre projects, the pads are drawn where the slave chain's forward kinematics puts them,
// and the slave's links (URDF-style meshes, boxes between joint origins, the GP7's collision
// meshes) where its chain frames are.
#include "hapsim/render/world_scene.h"

#include "hapsim/geometry/procedural.h"
#include "hapsim/kinematics/procedural_motoman.h"
#include "hapsim/render/image_compare.h"
#include "hapsim/render/renderer.h"
#include "hapsim/render/slave_figure.h"
#include "hapsim/rig/rig_controller.h"
#include "hapsim/rig/rig_world.h"
#include "hapsim/runtime/world_snapshot.h"
#include "hapsim/scene/scene_file.h"
#include "hapsim/scene/teleop_setup.h"
#include "render/gl_test_context.h"
#include "support/test_data.h"

#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <memory>
#include <tuple>

namespace hapsim {
namespace {

using test::pixel_at;

constexpr int kW = 320;
constexpr int kH = 240;

// The default teleop scene (procedural Motoman, ball on the floor, sheet on a frame), stepped
// through its whole scripted pick-and-place: the ball ends resting in a dent of the sheet.
class WorldSceneRigTest : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    const SceneDescription scene =
        load_scene(std::filesystem::path(HAPSIM_SOURCE_DIR) / "scenes" / "teleop.json");
    setup_ = std::make_unique<TeleopSetup>(make_rig_setup(scene, std::nullopt, false));
    world_ = std::make_unique<World>(setup_->description);
    const Trajectory& t = setup_->trajectory;
    const double dt = 1e-3;
    const auto steps = static_cast<int>((t.end_time_s() - t.start_time_s()) / dt);
    for (int k = 1; k <= steps; ++k) {
      static_cast<void>(world_->step(t.sample_at(t.start_time_s() + k * dt), dt));
    }
    gl_.open(kW, kH);
  }
  static void TearDownTestSuite() {
    gl_.close();
    world_.reset();
    setup_.reset();
  }
  void require_gl() {
    if (!gl_.context) {
      GTEST_SKIP() << "no offscreen GL context: " << gl_.why_not;
    }
  }
  static std::vector<std::uint8_t> render(const RenderScene& scene, const OrbitCamera& cam) {
    gl_.renderer->draw(scene, cam, kW, kH);
    return gl_.context->read_rgba();
  }
  static bool dominant(const test::Pixel& p, int channel, int margin) {
    const int c[3] = {p.r, p.g, p.b};
    return c[channel] > c[(channel + 1) % 3] + margin && c[channel] > c[(channel + 2) % 3] + margin;
  }

  static std::unique_ptr<TeleopSetup> setup_;
  static std::unique_ptr<World> world_;
  static test::SharedGl gl_;
};

std::unique_ptr<TeleopSetup> WorldSceneRigTest::setup_;
std::unique_ptr<World> WorldSceneRigTest::world_;
test::SharedGl WorldSceneRigTest::gl_;

TEST_F(WorldSceneRigTest, SheetMeshHoldsTheWorldsDentedHeights) {
  const World& world = *world_;
  ASSERT_GT(world.sheet(rig_description(world.description())->sheet_body)->max_depth_m(), 1e-4)
      << "the ball should rest in a dent";
  WorldScene from_world(world);
  from_world.update_from_world(world);
  WorldScene from_snapshot(world);
  from_snapshot.update(make_world_snapshot(world));
  const auto heights =
      world.sheet(rig_description(world.description())->sheet_body)->surface_heights();
  const TriangleMesh& rest = world.sheet(rig_description(world.description())->sheet_body)->mesh();
  const std::size_t flat =
      world
          .flat_segment(BodyIndex{rig_description(world.description())->sheet_body},
                        LocalSegment{0})
          .index();
  for (const WorldScene* scene : {&from_world, &from_snapshot}) {
    const RenderMesh& sheet = scene->scene().mesh(scene->segment_mesh(flat));
    ASSERT_EQ(sheet.geometry().vertices.size(), heights.size());
    // A snapshot carries positions as float.
    const bool exact = scene == &from_world;
    for (std::size_t k = 0; k < heights.size(); ++k) {
      const Vec3& v = sheet.geometry().vertices[k];
      ASSERT_EQ(v.z(), exact ? heights[k] : static_cast<double>(static_cast<float>(heights[k])))
          << "node " << k;
      ASSERT_NEAR(v.x(), rest.vertices[k].x(), exact ? 0.0 : 1e-7);
      ASSERT_NEAR(v.y(), rest.vertices[k].y(), exact ? 0.0 : 1e-7);
    }
    EXPECT_TRUE(sheet.X_world_mesh.isApprox(
        rig_description(world.description())->environment.X_world_sheet, 0.0));
  }
  // The dent is under the ball: the node nearest the ball's footprint is the deepest around.
  const Vec3 ball_sheet =
      rig_description(world.description())->environment.X_world_sheet.inverse() *
      world.body_pose(rig_description(world.description())->ball_body).translation();
  const int n = world.sheet(rig_description(world.description())->sheet_body)->nodes_per_side();
  const double h = world.sheet(rig_description(world.description())->sheet_body)->spacing_m();
  const auto i = static_cast<int>(
      std::lround((ball_sheet.x() +
                   0.5 * world.sheet(rig_description(world.description())->sheet_body)->side_m()) /
                  h));
  const auto j = static_cast<int>(
      std::lround((ball_sheet.y() +
                   0.5 * world.sheet(rig_description(world.description())->sheet_body)->side_m()) /
                  h));
  ASSERT_TRUE(i >= 0 && i < n && j >= 0 && j < n);
  EXPECT_LT(heights[static_cast<std::size_t>(j * n + i)],
            -0.5 * world.sheet(rig_description(world.description())->sheet_body)->max_depth_m());
}

TEST_F(WorldSceneRigTest, BallColourAppearsWhereItsCentreProjects) {
  require_gl();
  const World& world = *world_;
  WorldScene scene(world);
  scene.update_from_world(world);
  // Look at the ball from beyond it (the robot behind it), a little from above.
  const std::size_t ball_body = rig_description(world.description())->ball_body;
  const Vec3 ball = world.body_pose(ball_body).translation();
  OrbitCamera cam;
  cam.target_world = ball;
  cam.yaw_rad = std::atan2(ball.y(), ball.x());
  cam.pitch_rad = 0.4;
  cam.distance_m = 0.8;
  const Vec3 px = cam.project(ball, kW, kH);
  ASSERT_TRUE(px.x() > 0 && px.x() < kW && px.y() > 0 && px.y() < kH);
  const auto x = static_cast<int>(px.x());
  const auto y = static_cast<int>(px.y());
  const auto with_ball = render(scene.scene(), cam);
  EXPECT_TRUE(dominant(pixel_at(with_ball, kW, x, y), 0, 60))
      << "pixel " << x << "," << y << " = " << pixel_at(with_ball, kW, x, y).r << " "
      << pixel_at(with_ball, kW, x, y).g << " " << pixel_at(with_ball, kW, x, y).b;
  // The ball is drawn where its body is; without it the red is gone (it was the ball, not the
  // robot or the background).
  const std::size_t flat = world.flat_segment(BodyIndex{ball_body}, LocalSegment{0}).index();
  EXPECT_TRUE(scene.scene()
                  .mesh(scene.segment_mesh(flat))
                  .X_world_mesh.isApprox(world.body_pose(ball_body), 0.0));
  scene.set_segment_visible(flat, false);
  const auto without = render(scene.scene(), cam);
  EXPECT_FALSE(dominant(pixel_at(without, kW, x, y), 0, 60));
}

TEST_F(WorldSceneRigTest, BallsImprintShowsInTheDrawnSheet) {
  require_gl();
  const World& world = *world_;
  const TeleopRigDescription& rig = *rig_description(world.description());
  // Only the sheet, from a little above, around where the ball rests: once as the world left it
  // (the ball's dent), once at rest (a world not stepped).
  const World flat(world.description());
  const Vec3 ball = world.body_pose(rig.ball_body).translation();
  OrbitCamera cam;
  cam.target_world = ball - Vec3(0.0, 0.0, rig.ball.radius_m);
  cam.yaw_rad = 0.3;
  cam.pitch_rad = 0.35;
  cam.distance_m = 0.25;
  std::vector<std::vector<std::uint8_t>> images;
  for (const World* w : {&world, static_cast<const World*>(&flat)}) {
    WorldScene scene(*w);
    scene.update_from_world(*w);
    RenderScene& rs = scene.scene();
    for (std::size_t i = 0; i < scene.segment_count(); ++i) {
      scene.set_segment_visible(
          i, i == world.flat_segment(BodyIndex{rig.sheet_body}, LocalSegment{0}).index());
    }
    rs.spheres.clear();
    rs.segments.clear();
    rs.shadow_marks.clear();
    rs.floor.visible = false;
    images.push_back(render(rs, cam));
  }
  // The dent (a fraction of a millimetre, drawn darker by its depth) shows where the ball sat.
  const ImageDiff d = compare_images(images[0], images[1], kW, kH);
  EXPECT_GT(d.differing_fraction, 0.01);
  const Vec3 px = cam.project(ball - Vec3(0.0, 0.0, rig.ball.radius_m), kW, kH);
  const test::Pixel dented =
      pixel_at(images[0], kW, static_cast<int>(px.x()), static_cast<int>(px.y()));
  const test::Pixel at_rest =
      pixel_at(images[1], kW, static_cast<int>(px.x()), static_cast<int>(px.y()));
  EXPECT_NE(std::tuple(dented.r, dented.g, dented.b), std::tuple(at_rest.r, at_rest.g, at_rest.b));
}

TEST_F(WorldSceneRigTest, PadsAreDrawnWhereTheChainsForwardKinematicsPutsThem) {
  require_gl();
  const World& world = *world_;
  WorldScene scene(world);
  scene.update_from_world(world);
  const auto pad_mesh = [&](int i) {
    return scene.segment_mesh(
        world
            .flat_segment(
                BodyIndex{
                    rig_description(world.description())->pad_body[static_cast<std::size_t>(i)]},
                LocalSegment{0})
            .index());
  };
  // Independent geometry: the tool from the chain's FK, the pads across its y at the pad depth.
  const Iso3 X_tool = rig_state(world)->slave->chain().forward(rig_state(world)->slave->q());
  const ParallelGripperParams& p = rig_description(world.description())->gripper;
  const double w = rig_state(world)->result.gripper.width_m;
  const Vec3 pad_world[2] = {X_tool * Vec3(0.0, 0.5 * w + p.pad_half_m.y(), p.pad_depth_m),
                             X_tool * Vec3(0.0, -(0.5 * w + p.pad_half_m.y()), p.pad_depth_m)};
  for (int i = 0; i < 2; ++i) {
    const RenderMesh& pad = scene.scene().mesh(pad_mesh(i));
    EXPECT_LT((pad.X_world_mesh.translation() - pad_world[i]).norm(), 1e-12) << "pad " << i;
    EXPECT_TRUE(pad.X_world_mesh.linear().isApprox(X_tool.linear(), 1e-12));
  }
  // The shadow mark is under the tool point.
  ASSERT_EQ(scene.scene().shadow_marks.size(), 1u);
  EXPECT_LT(
      (scene.scene().shadow_marks[0].point_world - X_tool * Vec3(0.0, 0.0, p.pad_depth_m)).norm(),
      1e-12);

  // Only the pads, pure green: each pad's centre pixel is green.
  RenderScene& rs = scene.scene();
  for (MeshId id = 0; id < rs.mesh_count(); ++id) {
    rs.mesh(id).visible = false;
  }
  rs.spheres.clear();
  rs.segments.clear();
  rs.shadow_marks.clear();
  rs.floor.visible = false;
  rs.style.background = Vec3f::Zero();
  OrbitCamera cam;
  cam.target_world = 0.5 * (pad_world[0] + pad_world[1]);
  // Looking along the pads' face normals' perpendicular: from the tool's x side, a little above.
  const Vec3 side = X_tool.linear().col(0);
  cam.yaw_rad = std::atan2(side.y(), side.x());
  cam.pitch_rad = 0.3;
  cam.distance_m = 0.35;
  for (int i = 0; i < 2; ++i) {
    rs.mesh(pad_mesh(i)).visible = true;
    rs.mesh(pad_mesh(i)).colour = Vec3f(0.1f, 0.9f, 0.1f);
  }
  const auto image = render(rs, cam);
  for (int i = 0; i < 2; ++i) {
    const Vec3 px = cam.project(pad_world[i], kW, kH);
    const auto x = static_cast<int>(px.x());
    const auto y = static_cast<int>(px.y());
    ASSERT_TRUE(x >= 0 && x < kW && y >= 0 && y < kH);
    const test::Pixel c = pixel_at(image, kW, x, y);
    EXPECT_TRUE(dominant(c, 1, 40))
        << "pad " << i << " at " << x << "," << y << ": " << c.r << " " << c.g << " " << c.b;
  }
}

// The render meshes of the slave's links (its bodies off the tool frame), in chain order.
std::vector<MeshId> link_meshes(const World& world, const WorldScene& scene) {
  std::vector<MeshId> ids;
  for (const TeleopRigDescription::SlaveBody& s :
       rig_description(world.description())->slave_bodies) {
    if (s.frame != kToolFrame) {
      ids.push_back(
          scene.segment_mesh(world.flat_segment(BodyIndex{s.body}, LocalSegment{0}).index()));
    }
  }
  return ids;
}

// The middle of a mesh's vertices' bounds, world frame (a box's centre, however it turns).
Vec3 bounds_centre_world(const RenderMesh& m) {
  Box3 b;
  for (const Vec3& v : m.geometry().vertices) {
    b.extend(m.X_world_mesh * v);
  }
  return b.center();
}

TEST(WorldSceneRig, LinkMeshesFollowTheirChainFrames) {
  // The procedural Motoman with a mesh on joint 2's frame, as a URDF's collision meshes come.
  SerialChain chain = make_procedural_motoman();
  ChainLinkGeometry g;
  g.link = "forearm";
  g.frame = 2;
  g.X_frame_mesh = Iso3(Eigen::Translation3d(0.1, 0.0, 0.02));
  g.mesh = make_box(Vec3(0.1, 0.03, 0.03));
  chain.set_link_geometry({g});
  TeleopRigDescription d;
  d.slave = std::make_shared<const SerialChain>(std::move(chain));
  d.slave_start_rad = {0.3, -0.2, 0.4, 0.1, 0.5, -0.2};
  World world(rig_world(d));
  WorldScene scene(world);
  ASSERT_EQ(link_meshes(world, scene).size(), 1u);
  std::array<Iso3, kMaxChainJoints> frames;
  static_cast<void>(rig_state(world)->slave->chain().frames(rig_state(world)->slave->q(), frames));
  const RenderMesh& mesh = scene.scene().mesh(link_meshes(world, scene)[0]);
  EXPECT_TRUE(mesh.X_world_mesh.isApprox(frames[2] * g.X_frame_mesh, 1e-12));
  // The bounds frame the whole scene: the ball, the sheet and the master drawn beside.
  const Box3& b = scene.rest_bounds_world();
  EXPECT_TRUE(
      b.contains(world.body_pose(rig_description(world.description())->ball_body).translation()));
  EXPECT_TRUE(b.contains(scene.master_display_origin_world()));
}

TEST(WorldSceneRig, BoxLinksJoinTheJointOrigins) {
  TeleopRigDescription d;
  d.slave = std::make_shared<const SerialChain>(make_procedural_motoman());
  d.slave_start_rad = {0.3, -0.2, 0.4, 0.1, 0.5, -0.2};
  World world(rig_world(d));
  WorldScene scene(world);
  const SerialChain& chain = rig_state(world)->slave->chain();
  std::array<Iso3, kMaxChainJoints> frames;
  const Iso3 tip = chain.frames(rig_state(world)->slave->q(), frames);
  // A box spans one joint origin to the next (base, joints 0..n−1, tip; coinciding origins
  // get no box): its centroid is their midpoint, in chain order.
  std::vector<Vec3> origins{Vec3::Zero()};
  for (int k = 0; k < chain.dof(); ++k) {
    origins.push_back(frames[static_cast<std::size_t>(k)].translation());
  }
  origins.push_back(tip.translation());
  std::vector<Vec3> midpoints;
  for (std::size_t k = 1; k < origins.size(); ++k) {
    if ((origins[k] - origins[k - 1]).norm() > 1e-6) {
      midpoints.push_back(0.5 * (origins[k] + origins[k - 1]));
    }
  }
  const std::vector<MeshId> links = link_meshes(world, scene);
  ASSERT_EQ(links.size(), midpoints.size());
  for (std::size_t l = 0; l < midpoints.size(); ++l) {
    const RenderMesh& m = scene.scene().mesh(links[l]);
    EXPECT_LT((bounds_centre_world(m) - midpoints[l]).norm(), 1e-9) << "link box " << l;
    // The boxes collide; the figure draws the links: hidden.
    EXPECT_FALSE(m.visible) << "link box " << l;
  }
  // Drawn instead as rounded links over the same joint origins (after the base plate), then a
  // drum centred on each joint, along its axis.
  ASSERT_NE(scene.slave_figure(), nullptr);
  EXPECT_TRUE(scene.slave_figure()->draws_links());
  EXPECT_FALSE(scene.slave_figure()->uses_visual_meshes());
  const auto& capsules = scene.scene().capsules;
  ASSERT_GE(capsules.size(), 1 + midpoints.size() + static_cast<std::size_t>(chain.dof()));
  for (std::size_t l = 0; l < midpoints.size(); ++l) {
    const RenderCapsule& c = capsules[1 + l];
    EXPECT_LT((0.5 * (c.a_world + c.b_world) - midpoints[l]).norm(), 1e-9) << "rounded link " << l;
    EXPECT_EQ(c.colour, RigColours{}.robot);
  }
  for (int k = 0; k < chain.dof(); ++k) {
    const RenderCapsule& drum = capsules[1 + midpoints.size() + static_cast<std::size_t>(k)];
    const auto kk = static_cast<std::size_t>(k);
    EXPECT_LT((0.5 * (drum.a_world + drum.b_world) - frames[kk].translation()).norm(), 1e-12);
    const Vec3 axis_world = frames[kk].linear() * chain.joints()[kk].axis;
    EXPECT_NEAR(std::abs((drum.b_world - drum.a_world).normalized().dot(axis_world)), 1.0, 1e-12);
  }
}

}  // namespace
}  // namespace hapsim

namespace hapsim {
namespace {

TEST(WorldSceneRig, Gp7CollisionMeshesArePosedAtTheirChainFrames) {
  const auto data = test::data_path("motoman_gp7");
  HAPSIM_SKIP_WITHOUT_DATA(std::filesystem::exists(data / "gp7.urdf"),
                           "Motoman GP7 URDF not found in " << data);
  SceneLoadOptions o;
  o.data_dir = data;
  const SceneDescription scene =
      load_scene(std::filesystem::path(HAPSIM_SOURCE_DIR) / "scenes" / "teleop_gp7.json", o);
  const TeleopSetup setup = make_rig_setup(scene, std::nullopt, /*load_link_meshes=*/true);
  const SerialChain& chain = *rig_description(setup.description)->slave;
  ASSERT_FALSE(chain.link_geometry().empty());
  World world(setup.description);
  WorldScene drawn(world);
  std::array<Iso3, kMaxChainJoints> frames;
  static_cast<void>(chain.frames(rig_state(world)->slave->q(), frames));
  const std::vector<MeshId> links = link_meshes(world, drawn);
  std::size_t l = 0;
  for (const ChainLinkGeometry& g : chain.link_geometry()) {
    if (g.mesh.empty()) {
      continue;
    }
    ASSERT_LT(l, links.size());
    const RenderMesh& m = drawn.scene().mesh(links[l++]);
    const Iso3 X_world_frame =
        g.frame < 0 ? Iso3::Identity() : frames[static_cast<std::size_t>(g.frame)];
    EXPECT_TRUE(m.X_world_mesh.isApprox(X_world_frame * g.X_frame_mesh, 1e-12)) << g.link;
    EXPECT_EQ(m.geometry().vertices.size(), g.mesh.vertices.size()) << g.link;
  }
  EXPECT_EQ(l, links.size());
  // Drawn from the URDF's visual meshes (not the collision hulls, which are hidden), each at its
  // link's chain frame, in the URDF material's colour (Yaskawa blue).
  ASSERT_NE(drawn.slave_figure(), nullptr);
  EXPECT_TRUE(drawn.slave_figure()->uses_visual_meshes()) << drawn.warnings().size();
  EXPECT_TRUE(drawn.warnings().empty());
  EXPECT_EQ(chain.link_visuals().size(), 7u);
  for (const MeshId id : links) {
    EXPECT_FALSE(drawn.scene().mesh(id).visible);
  }
  std::size_t visuals_seen = 0;
  for (MeshId id = 0; id < drawn.scene().mesh_count(); ++id) {
    const RenderMesh& m = drawn.scene().mesh(id);
    for (const ChainLinkVisual& v : chain.link_visuals()) {
      if (m.name != "slave/" + v.link) {
        continue;
      }
      ++visuals_seen;
      const Iso3 X_world_frame =
          v.frame < 0 ? Iso3::Identity() : frames[static_cast<std::size_t>(v.frame)];
      EXPECT_TRUE(m.X_world_mesh.isApprox(X_world_frame * v.X_frame_mesh, 1e-12)) << v.link;
      EXPECT_NEAR(m.colour.z(), 0.749f, 1e-3) << v.link;
      EXPECT_TRUE(m.visible);
    }
  }
  EXPECT_EQ(visuals_seen, chain.link_visuals().size());
  EXPECT_TRUE(drawn.rest_bounds_world().contains(frames[0].translation()));
}

}  // namespace
}  // namespace hapsim
