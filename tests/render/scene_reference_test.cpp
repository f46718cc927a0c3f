// Offscreen pictures of the shipped scenes in each display mode against checked-in reference
// images, within a tolerance (Mesa's software rasteriser may move a few levels between versions).
// The state drawn is deterministic: the scene's own scripted device stepped for a fixed number of
// cycles. Regenerate the references after an intended change of the picture with
//   HAPSIM_UPDATE_REFERENCES=1 build/release/tests/hapsim_render_tests
//   --gtest_filter='SceneReference*'
// and look at them (tests/render/reference/README.md).
#include "hapsim/render/image_compare.h"
#include "hapsim/render/png_image.h"
#include "hapsim/render/snapshot_writer.h"
#include "hapsim/render/world_scene.h"
#include "hapsim/rig/rig_controller.h"
#include "hapsim/scene/run_setup.h"
#include "hapsim/scene/scene_device.h"
#include "hapsim/scene/scene_file.h"
#include "hapsim/scene/teleop_setup.h"
#include "hapsim/world/world.h"
#include "support/test_data.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cstdlib>
#include <filesystem>
#include <numbers>
#include <string_view>

namespace hapsim {
namespace {

constexpr int kWidth = 320;
constexpr int kHeight = 180;

std::filesystem::path reference_dir() {
  return std::filesystem::path(HAPSIM_SOURCE_DIR) / "tests" / "render" / "reference";
}

// Only "1" rewrites the pictures: any other value (0, empty) compares, so a stray
// HAPSIM_UPDATE_REFERENCES=0 cannot turn these tests into passes that compared nothing.
bool updating() {
  const char* v = std::getenv("HAPSIM_UPDATE_REFERENCES");
  return v != nullptr && std::string_view(v) == "1";
}

std::unique_ptr<SnapshotWriter> make_writer() {
  try {
    return std::make_unique<SnapshotWriter>(kWidth, kHeight, 1);
  } catch (const std::exception& e) {
    return nullptr;
  }
}

// Compares (or, when updating, writes) one reference image; returns the picture.
std::vector<std::uint8_t> check_reference(SnapshotWriter& writer, const RenderScene& scene,
                                          const OrbitCamera& camera, const std::string& name) {
  const std::vector<std::uint8_t> pixels = writer.render(scene, camera);
  const std::filesystem::path path = reference_dir() / (name + ".png");
  if (updating()) {
    write_png(path.string(), kWidth, kHeight, pixels);
    return pixels;
  }
  const RgbaImage reference = read_png(path.string());
  EXPECT_EQ(reference.width, kWidth);
  EXPECT_EQ(reference.height, kHeight);
  const ImageDiff d = compare_images(pixels, reference.rgba, kWidth, kHeight);
  ImageTolerance tolerance;
  tolerance.max_mean_abs_diff = 2.0;
  tolerance.max_differing_fraction = 0.01;
  EXPECT_TRUE(d.within(tolerance)) << name << ": " << d.describe() << " (write this run's picture "
                                   << "with HAPSIM_UPDATE_REFERENCES=1 and compare)";
  return pixels;
}

TEST(SceneReference, KneeInEachDisplayModeMatchesTheReferences) {
  auto writer = make_writer();
  if (!writer) {
    GTEST_SKIP() << "no EGL context on this machine";
  }
  const SceneDescription scene =
      load_scene(std::filesystem::path(HAPSIM_SOURCE_DIR) / "scenes" / "knee_procedural.json");
  World world(scene.world);
  auto device = make_scene_device(scene, world);
  WorldScene view(world);
  const OrbitCamera camera =
      framed_camera(view.rest_bounds_world(), static_cast<double>(kWidth) / kHeight, 1.95, 0.3);
  view.update_from_world(world);
  const std::vector<std::uint8_t> rest = writer->render(view.scene(), camera);
  // 3.5 s into the script the fingertip presses the skin over the patella (~10 mm dent).
  for (int i = 0; i < 3500; ++i) {
    world.step(device->read(i * scene.run.dt_s), scene.run.dt_s);
  }
  ASSERT_GT(world.current_deflection_m(0, world.segment_count(0) - 1), 0.005);
  view.update_from_world(world);
  std::vector<std::vector<std::uint8_t>> pictures;
  for (const DisplayMode mode : {DisplayMode::kFaces, DisplayMode::kLines, DisplayMode::kPoints}) {
    view.scene().style.display_mode = mode;
    pictures.push_back(
        check_reference(*writer, view.scene(), camera, std::string("knee_") + to_string(mode)));
  }
  // Independent of the references: the modes really differ, and the pressed knee is not the
  // knee at rest (the dent and the tool).
  EXPECT_GT(compare_images(pictures[0], pictures[1], kWidth, kHeight).differing_fraction, 0.02);
  EXPECT_GT(compare_images(pictures[1], pictures[2], kWidth, kHeight).differing_fraction, 0.02);
  EXPECT_GT(compare_images(pictures[0], rest, kWidth, kHeight).differing_fraction, 0.001);
}

TEST(SceneReference, KneeSegmentAndGroupColoursMatchTheReferences) {
  auto writer = make_writer();
  if (!writer) {
    GTEST_SKIP() << "no EGL context on this machine";
  }
  const SceneDescription scene =
      load_scene(std::filesystem::path(HAPSIM_SOURCE_DIR) / "scenes" / "knee_procedural.json");
  World world(scene.world);
  WorldSceneOptions o;
  o.colouring = SegmentColouring::kSegments;
  WorldScene view(world, o);
  // The skin hides the rest: show what is under it, as the knee paper's Fig. 3 does.
  view.set_segment_visible(
      world.flat_segment(BodyIndex{0}, LocalSegment{world.segment_count(0) - 1}).index(), false);
  const OrbitCamera camera =
      framed_camera(view.rest_bounds_world(), static_cast<double>(kWidth) / kHeight, 1.95, 0.3);
  view.update_from_world(world);
  const auto segments = check_reference(*writer, view.scene(), camera, "knee_segments");
  o.colouring = SegmentColouring::kGroups;
  view.set_options(o);
  const auto groups = check_reference(*writer, view.scene(), camera, "knee_groups");
  EXPECT_GT(compare_images(segments, groups, kWidth, kHeight).differing_fraction, 0.05);
}

TEST(SceneReference, TeleopInEachDisplayModeMatchesTheReferences) {
  auto writer = make_writer();
  if (!writer) {
    GTEST_SKIP() << "no EGL context on this machine";
  }
  const SceneDescription scene =
      load_scene(std::filesystem::path(HAPSIM_SOURCE_DIR) / "scenes" / "teleop.json");
  TeleopSetup setup = make_rig_setup(scene, std::nullopt, false);
  World world(setup.description);
  // 6 s into the scripted pick-and-place the gripper carries the ball towards the sheet.
  const double dt = scene.run.dt_s;
  for (int k = 1; k <= 6000; ++k) {
    world.step(setup.trajectory.sample_at(setup.trajectory.start_time_s() + k * dt), dt);
  }
  ASSERT_TRUE(rig_state(world)->held);
  WorldScene view(world);
  view.update_from_world(world);
  const OrbitCamera camera =
      framed_camera(view.rest_bounds_world(), static_cast<double>(kWidth) / kHeight, -0.9, 0.45);
  std::vector<std::vector<std::uint8_t>> pictures;
  for (const DisplayMode mode : {DisplayMode::kFaces, DisplayMode::kLines, DisplayMode::kPoints}) {
    view.scene().style.display_mode = mode;
    pictures.push_back(
        check_reference(*writer, view.scene(), camera, std::string("teleop_") + to_string(mode)));
  }
  // The robot and the master are rods in every mode: the rest (ball, sheet, pads) differs.
  EXPECT_GT(compare_images(pictures[0], pictures[1], kWidth, kHeight).differing_fraction, 0.002);
  EXPECT_GT(compare_images(pictures[1], pictures[2], kWidth, kHeight).differing_fraction, 0.005);
  // The ball is where the world says, in its colour (red), in the face picture.
  const Vec3 px =
      camera.project(world.body_pose(rig_description(world.description())->ball_body).translation(),
                     kWidth, kHeight);
  const auto x = static_cast<int>(px.x());
  const auto y = static_cast<int>(px.y());
  ASSERT_TRUE(x >= 0 && x < kWidth && y >= 0 && y < kHeight);
  const std::uint8_t* p = &pictures[0][(static_cast<std::size_t>(y) * kWidth + x) * 4];
  EXPECT_GT(p[0], 2 * p[1]) << "no red ball at its projection";
}

// A teleoperation scene stepped `steps` cycles on its scripted pick-and-place (−1: all of it).
std::unique_ptr<World> stepped_teleop(const SceneDescription& scene, int steps) {
  TeleopSetup setup = make_rig_setup(scene, std::nullopt, true);
  auto world = std::make_unique<World>(setup.description);
  const double dt = scene.run.dt_s;
  const Trajectory& t = setup.trajectory;
  if (steps < 0) {
    steps = static_cast<int>((t.end_time_s() - t.start_time_s()) / dt);
  }
  for (int k = 1; k <= steps; ++k) {
    world->step(setup.trajectory.sample_at(setup.trajectory.start_time_s() + k * dt), dt);
  }
  return world;
}

TEST(SceneReference, Gp7DrawnFromItsVisualMeshesMatchesTheReference) {
  const auto data = test::data_path("motoman_gp7");
  HAPSIM_SKIP_WITHOUT_DATA(std::filesystem::exists(data / "gp7.urdf"),
                           "Motoman GP7 URDF not found in " << data);
  auto writer = make_writer();
  if (!writer) {
    GTEST_SKIP() << "no EGL context on this machine";
  }
  SceneLoadOptions o;
  o.data_dir = data;
  const SceneDescription scene =
      load_scene(std::filesystem::path(HAPSIM_SOURCE_DIR) / "scenes" / "teleop_gp7.json", o);
  const auto world = stepped_teleop(scene, 6000);
  WorldScene view(*world);
  view.update_from_world(*world);
  const OrbitCamera camera =
      framed_camera(view.rest_bounds_world(), static_cast<double>(kWidth) / kHeight, -0.9, 0.45);
  check_reference(*writer, view.scene(), camera, "teleop_gp7");
}

TEST(SceneReference, BallsImprintInTheSheetMatchesTheReference) {
  auto writer = make_writer();
  if (!writer) {
    GTEST_SKIP() << "no EGL context on this machine";
  }
  const SceneDescription scene =
      load_scene(std::filesystem::path(HAPSIM_SOURCE_DIR) / "scenes" / "teleop.json");
  // The whole pick-and-place: the ball rests in its dent on the sheet (the ball hidden).
  auto world = stepped_teleop(scene, -1);
  const TeleopRigDescription& rig = *rig_description(world->description());
  const Vec3 ball = world->body_pose(rig.ball_body).translation();
  WorldScene view(*world);
  view.update_from_world(*world);
  // Only the sheet, from above at the ball's side: its grid bends and darkens into the dent.
  for (std::size_t i = 0; i < view.segment_count(); ++i) {
    view.set_segment_visible(
        i, i == world->flat_segment(BodyIndex{rig.sheet_body}, LocalSegment{0}).index());
  }
  view.scene().capsules.clear();
  view.scene().spheres.clear();
  OrbitCamera camera;
  camera.target_world = ball - Vec3(0.0, 0.0, rig.ball.radius_m);
  camera.yaw_rad = -0.9;
  camera.pitch_rad = 0.7;
  camera.distance_m = 0.3;
  const auto dented = check_reference(*writer, view.scene(), camera, "sheet_imprint");
  // Independent of the reference: the same view of a sheet at rest differs around the ball.
  const World flat(world->description());
  WorldScene rest(flat);
  rest.update_from_world(flat);
  for (std::size_t i = 0; i < rest.segment_count(); ++i) {
    rest.set_segment_visible(
        i, i == flat.flat_segment(BodyIndex{rig.sheet_body}, LocalSegment{0}).index());
  }
  rest.scene().capsules.clear();
  rest.scene().spheres.clear();
  const auto at_rest = writer->render(rest.scene(), camera);
  EXPECT_GT(compare_images(dented, at_rest, kWidth, kHeight).differing_fraction, 0.01);
}

// A glove scene stepped `steps` cycles on its own script, framed on everything drawn (the hand
// included), in faces.
std::vector<std::uint8_t> glove_scene_picture(SnapshotWriter& writer, const std::string& file,
                                              int steps, double yaw, double pitch,
                                              const std::string& name) {
  // As `hapsim run` assembles it (materials no stiffer than the glove's rating).
  RunSetup run = make_run_setup(
      load_scene(std::filesystem::path(HAPSIM_SOURCE_DIR) / "scenes" / file), DeviceChoice{});
  World& world = *run.world;
  const double dt = run.scene.run.dt_s;
  for (int i = 0; i < steps; ++i) {
    world.step(run.device->read(i * dt), dt);
  }
  WorldScene view(world);
  view.update_from_world(world);
  EXPECT_FALSE(view.scene().capsules.empty()) << file << ": no hand drawn";
  const OrbitCamera camera =
      framed_camera(view.scene().bounds_world(), static_cast<double>(kWidth) / kHeight, yaw, pitch);
  return check_reference(writer, view.scene(), camera, name);
}

TEST(SceneReference, StereoModesMatchTheReferences) {
  auto writer = make_writer();
  if (!writer) {
    GTEST_SKIP() << "no EGL context on this machine";
  }
  const SceneDescription scene =
      load_scene(std::filesystem::path(HAPSIM_SOURCE_DIR) / "scenes" / "teleop.json");
  const auto world = stepped_teleop(scene, 6000);
  WorldScene view(*world);
  view.update_from_world(*world);
  const OrbitCamera camera =
      framed_camera(view.rest_bounds_world(), static_cast<double>(kWidth) / kHeight, -0.9, 0.45);
  writer->set_stereo(StereoMode::kSideBySide, 0.0);
  check_reference(*writer, view.scene(), camera, "teleop_side_by_side");
  writer->set_stereo(StereoMode::kAnaglyph, 0.0);
  check_reference(*writer, view.scene(), camera, "teleop_anaglyph");
}

TEST(SceneReference, NamedViewMatchesTheReference) {
  auto writer = make_writer();
  if (!writer) {
    GTEST_SKIP() << "no EGL context on this machine";
  }
  RunSetup run = make_run_setup(
      load_scene(std::filesystem::path(HAPSIM_SOURCE_DIR) / "scenes" / "knee_hand_procedural.json"),
      DeviceChoice{});
  World& world = *run.world;
  for (int i = 0; i < 1600; ++i) {
    world.step(run.device->read(i * run.scene.run.dt_s), run.scene.run.dt_s);
  }
  WorldScene view(world);
  view.update_from_world(world);
  // The scene's "fig6" view: the knee paper's Fig. 6, the hand at the front of the knee.
  const auto fig6 = std::find_if(run.scene.views.begin(), run.scene.views.end(),
                                 [](const SceneView& v) { return v.name == "fig6"; });
  ASSERT_NE(fig6, run.scene.views.end());
  const OrbitCamera camera =
      OrbitCamera::looking_at(fig6->eye_m, fig6->target_m, fig6->fov_deg * std::numbers::pi / 180);
  check_reference(*writer, view.scene(), camera, "knee_hand_fig6");
}

TEST(SceneReference, GloveHandScenesMatchTheReferences) {
  auto writer = make_writer();
  if (!writer) {
    GTEST_SKIP() << "no EGL context on this machine";
  }
  // The knee paper's Fig. 6: the hand's index and middle fingers pressing the knee, 1.6 s in.
  glove_scene_picture(*writer, "knee_hand_procedural.json", 1600, 1.2, 0.35, "knee_hand");
  // The hand carrying the ball between thumb and index.
  glove_scene_picture(*writer, "hand_ball_sheet.json", 2500, -1.2, 0.6, "hand_ball_sheet");
}

}  // namespace
}  // namespace hapsim
