// The viewer's session for a World scene, without a window: the mouse probe's input reaches the
// haptic thread and its force comes back in the readout (Hooke's law on a penalty sphere), a
// stiffness change from the control area takes effect live, recording writes a file that reads
// back with the world's hash, and an unknown device or a missing 3D mouse is a clear error.
#include "hapsim/ui/world_viewer_session.h"

#include "hapsim/core/error.h"
#include "hapsim/device/interactive_device.h"
#include "hapsim/device/recording.h"
#include "hapsim/geometry/procedural.h"
#include "hapsim/scene/scene_description.h"
#include "hapsim/world/world.h"

#include "support/replay_check.h"

#include <gtest/gtest.h>

#include <unistd.h>
#include <chrono>
#include <cmath>
#include <filesystem>
#include <functional>
#include <thread>

namespace hapsim {
namespace {

// A soft (penalty) sphere of radius 30 mm at the origin, k = 300 N/m, rigid (no deflection, so
// the force is exactly k·depth), and one point-like tool on the omega.3's limits.
SceneDescription soft_sphere_scene() {
  SceneDescription scene;
  scene.file = "soft_sphere.json";
  scene.device.profile = "omega3";
  MaterialDescription m;
  m.name = "muscle";
  m.response = ContactResponse::kPenalty;
  m.contact.stiffness_n_per_m = 300.0;
  m.contact.max_penetration_m = 0.02;
  m.contact.max_force_n = 10.0;
  scene.world.materials.push_back(m);
  BodyDescription body;
  body.name = "ball";
  body.kind = BodyKind::kStatic;
  SegmentDescription seg;
  seg.name = "sphere";
  seg.mesh = make_uv_sphere(0.03, 96, 48);
  body.segments.push_back(std::move(seg));
  scene.world.bodies.push_back(std::move(body));
  ToolDescription tool;
  tool.name = "tip";
  tool.radius_m = 0.0;
  scene.world.tools.push_back(tool);
  return scene;
}

// Calls session.update() (as the viewer's frame loop does) until `holds` is true. The test asserts
// on the condition; the 120 s limit only bounds a hang (a busy machine, or a sanitizer build
// several times slower, may take any time: 10 s was not enough under ASan).
[[nodiscard]] bool eventually(ViewerSession& session, const std::function<bool()>& holds) {
  const auto give_up = std::chrono::steady_clock::now() + std::chrono::seconds(120);
  while (true) {
    session.update();
    if (holds()) {
      return true;
    }
    if (std::chrono::steady_clock::now() > give_up) {
      return false;
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(2));
  }
}

// The readout's force on the one tool (0 before the first snapshot arrived).
double readout_force_n(const ViewerSession& session) {
  const auto& tools = session.readout().tools;
  return tools.empty() ? 0.0 : tools[0].force_n;
}

TEST(WorldViewerSession, MouseProbeForceFollowsHookeAndLiveStiffness) {
  ViewerConfig config;
  config.scene = "soft_sphere.json";
  config.device = "mouse";
  const auto session = make_world_viewer_session(config, soft_sphere_scene());
  InteractiveDevice* mouse = session->mouse_device();
  ASSERT_NE(mouse, nullptr);
  // 4 mm into the top of the sphere (the UV sphere's pole is a vertex: exact depth there).
  DeviceInput in;
  in.p_world = Vec3(0.0, 0.0, 0.026);
  mouse->set_input(in);
  // After more than 200 cycles the force settles at Hooke's k·x, in the readout and on the device.
  const auto settles_at = [&](double force_n, double tolerance_n) {
    const std::uint64_t from = session->loop_status().cycles;
    return [&session, mouse, from, force_n, tolerance_n] {
      return session->loop_status().cycles > from + 200 &&
             std::abs(readout_force_n(*session) - force_n) <= tolerance_n &&
             std::abs(mouse->last_command().force_world_n.z() - force_n) <= tolerance_n;
    };
  };
  EXPECT_TRUE(eventually(*session, settles_at(300.0 * 0.004, 0.02)))  // pushes up
      << "readout " << readout_force_n(*session) << " N, device "
      << mouse->last_command().force_world_n.transpose() << " N after "
      << session->loop_status().cycles << " cycles";
  ASSERT_EQ(session->readout().tools.size(), 1u);
  // The control area's stiffness change reaches the haptic thread: twice as stiff, twice the
  // force at the same depth.
  ContactMaterial stiffer = soft_sphere_scene().world.materials[0].contact;
  stiffer.stiffness_n_per_m = 600.0;
  ASSERT_TRUE(session->set_material_contact(0, stiffer));
  EXPECT_TRUE(eventually(*session, settles_at(600.0 * 0.004, 0.04)))
      << "readout " << readout_force_n(*session) << " N";
  EXPECT_FALSE(session->set_material_contact(7, stiffer));  // no such material
  // Out of the sphere: no force.
  in.p_world = Vec3(0.0, 0.0, 0.05);
  mouse->set_input(in);
  EXPECT_TRUE(eventually(*session, settles_at(0.0, 0.0)))
      << "readout " << readout_force_n(*session) << " N";
}

TEST(WorldViewerSession, RecordingWritesEveryCycleWithTheWorldsHash) {
  ViewerConfig config;
  config.scene = "soft_sphere.json";
  config.device = "mouse";
  const auto session = make_world_viewer_session(config, soft_sphere_scene());
  const auto path = std::filesystem::temp_directory_path() /
                    ("hapsim_view_rec_" + std::to_string(::getpid()) + ".rec");
  std::string error;
  ASSERT_TRUE(session->set_recording(&path, error)) << error;
  EXPECT_TRUE(session->recording());
  // The recording restarted the loop at cycle 0: record until well over 300 cycles.
  EXPECT_TRUE(eventually(*session, [&] { return session->loop_status().cycles > 400; }));
  ASSERT_TRUE(session->set_recording(nullptr, error));
  EXPECT_FALSE(session->recording());
  const Recording r = read_recording(path);
  EXPECT_GT(r.frames.size(), 300u);
  for (std::size_t i = 1; i < r.frames.size(); ++i) {
    ASSERT_EQ(r.frames[i].cycle_index, r.frames[i - 1].cycle_index + 1);  // none dropped
  }
  World reference(soft_sphere_scene().world);
  EXPECT_EQ(r.header.scene_hash, reference.content_hash());
  // It starts at the scene's start (cycle 0) and replays on a fresh world bit for bit (a viewer
  // recording used to fail at frame 0: its cycles were numbered from the session's start).
  EXPECT_EQ(r.frames.front().cycle_index, 0u);
  EXPECT_TRUE(test::replays_bit_for_bit(soft_sphere_scene(), path));
  std::filesystem::remove(path);
  const std::filesystem::path bad = "/nonexistent/dir/x.rec";
  EXPECT_FALSE(session->set_recording(&bad, error));
  EXPECT_NE(error.find("/nonexistent/dir/x.rec"), std::string::npos) << error;
}

// The mouse probe 4 mm into the sphere's top: the recordings below hold a force, not zeros.
InteractiveDevice& press_into_the_sphere(ViewerSession& session) {
  InteractiveDevice* mouse = session.mouse_device();
  EXPECT_NE(mouse, nullptr);
  DeviceInput in;
  in.p_world = Vec3(0.0, 0.0, 0.026);
  mouse->set_input(in);
  return *mouse;
}

// Every frame of a recording, numbered 0, 1, 2, ... (none missing, none from before it began).
void expect_numbered_from_zero(const Recording& r) {
  ASSERT_FALSE(r.frames.empty());
  for (std::size_t i = 0; i < r.frames.size(); ++i) {
    ASSERT_EQ(r.frames[i].cycle_index, i);
  }
}

// Pausing ends a recording, as a reset does: after a pause the world forgets the tool's motion
// and the force comes back softly, which no replay of one continuous run does. The file up to the
// pause replays bit for bit, and resuming does not add to it.
TEST(WorldViewerSession, PausingEndsTheRecordingWhichReplaysUpToThePause) {
  ViewerConfig config;
  config.scene = "soft_sphere.json";
  const auto session = make_world_viewer_session(config, soft_sphere_scene());
  InteractiveDevice& mouse = press_into_the_sphere(*session);
  const auto path = std::filesystem::temp_directory_path() /
                    ("hapsim_view_pause_" + std::to_string(::getpid()) + ".rec");
  std::string error;
  ASSERT_TRUE(session->set_recording(&path, error)) << error;
  EXPECT_TRUE(eventually(*session, [&] {
    return session->loop_status().cycles > 300 && mouse.last_command().force_world_n.z() > 1.0;
  }));
  session->set_paused(true);
  EXPECT_FALSE(session->recording()) << "the recording went on through the pause";
  session->set_paused(false);
  const std::uint64_t resumed = session->loop_status().cycles;
  EXPECT_TRUE(eventually(*session, [&] { return session->loop_status().cycles > resumed + 300; }));
  (void)session->set_recording(nullptr, error);
  const Recording r = read_recording(path);
  expect_numbered_from_zero(r);
  EXPECT_LE(r.frames.size(), resumed + 1);                    // nothing after the pause
  EXPECT_GT(r.frames.back().command.force_world_n.z(), 1.0);  // it recorded the press
  EXPECT_TRUE(test::replays_bit_for_bit(soft_sphere_scene(), path));
  std::filesystem::remove(path);
}

// A recording started while paused begins with the first cycle that steps the world, as frame 0,
// and replays bit for bit (the paused cycles before it recorded nothing, and the soft start of the
// force on resuming is not in the recorded command).
TEST(WorldViewerSession, RecordingStartedWhilePausedBeginsAtTheFirstStep) {
  ViewerConfig config;
  config.scene = "soft_sphere.json";
  const auto session = make_world_viewer_session(config, soft_sphere_scene());
  InteractiveDevice& mouse = press_into_the_sphere(*session);
  session->set_paused(true);
  const auto path = std::filesystem::temp_directory_path() /
                    ("hapsim_view_paused_" + std::to_string(::getpid()) + ".rec");
  std::string error;
  ASSERT_TRUE(session->set_recording(&path, error)) << error;
  EXPECT_TRUE(eventually(*session, [&] { return session->loop_status().cycles > 100; }));
  EXPECT_TRUE(session->recording());
  session->set_paused(false);
  const std::uint64_t resumed = session->loop_status().cycles;
  EXPECT_TRUE(eventually(*session, [&] {
    return session->loop_status().cycles > resumed + 300 &&
           mouse.last_command().force_world_n.z() > 1.0;
  }));
  ASSERT_TRUE(session->set_recording(nullptr, error));
  const Recording r = read_recording(path);
  expect_numbered_from_zero(r);
  EXPECT_GT(r.frames.size(), 300u);
  EXPECT_TRUE(test::replays_bit_for_bit(soft_sphere_scene(), path));
  std::filesystem::remove(path);
}

TEST(WorldViewerSession, UnknownDeviceAndMissing3dMouseAreClearErrors) {
  ViewerConfig config;
  config.scene = "soft_sphere.json";
  config.device = "joystick";
  try {
    (void)make_world_viewer_session(config, soft_sphere_scene());
    FAIL() << "an unknown device was accepted";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("joystick"), std::string::npos) << e.what();
  }
  config.device = "spacemouse";
  try {
    (void)make_world_viewer_session(config, soft_sphere_scene());
    GTEST_SKIP() << "a 3D mouse answered here (spacenavd is running)";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("3D mouse"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace hapsim
