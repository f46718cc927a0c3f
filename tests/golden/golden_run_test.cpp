// Golden runs: every shipped scene, run as `hapsim run` runs it (the scene's own scripted device,
// its dt and length), must reproduce the trace recorded under tests/golden/ cycle by cycle: the
// same contacts per (tool, body, segment) and every force, torque and position within 1e-9. The
// traces were recorded before the one-world refactor, so this is what holds the refactor to the old
// behaviour; a deliberate change re-records them (HAPSIM_UPDATE_GOLDEN=1) and says why in its
// commit. Scenes on real data skip with a message when ../shared/data is absent.
#include "golden_trace.h"

#include "hapsim/core/data_dir.h"
#include "hapsim/core/device_profile.h"
#include "hapsim/device/recording.h"
#include "hapsim/runtime/session.h"
#include "hapsim/scene/scene_device.h"
#include "hapsim/scene/scene_file.h"
#include "hapsim/scene/teleop_setup.h"
#include "hapsim/world/world.h"

#include <gtest/gtest.h>
#include <unistd.h>

#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <optional>

namespace hapsim {
namespace {

namespace fs = std::filesystem;

constexpr double kTolerance = 1e-9;

const fs::path kScenes = fs::path(HAPSIM_SOURCE_DIR) / "scenes";
const fs::path kGolden = fs::path(HAPSIM_SOURCE_DIR) / "tests" / "golden";

// The scene's data folder (real data), or nullopt when the scene needs one that is absent.
std::optional<SceneLoadOptions> load_options(const std::string& data_folder) {
  SceneLoadOptions o;
  if (data_folder.empty()) {
    return o;
  }
  const auto root = find_data_dir(HAPSIM_TEST_DATA_DIR);
  if (!root || !fs::is_directory(*root / data_folder)) {
    return std::nullopt;
  }
  o.data_dir = *root / data_folder;
  return o;
}

// A haptic-world scene as `hapsim run` assembles it: the world no stiffer than the device's
// rating, the scene's scripted device, the session with the safety layer, every cycle recorded.
test::GoldenTrace run_world_scene(const SceneDescription& scene, const std::string& name) {
  const DeviceProfile& profile = device_profile(scene.device.profile);
  WorldOptions world_options;
  world_options.max_stiffness_n_per_m = profile.max_stiffness_n_per_m;
  World world(scene.world, world_options);
  auto device = make_scene_device(scene, world);
  const double duration_s =
      scene.run.duration_s > 0.0 ? scene.run.duration_s : device->duration_end_s();
  const fs::path rec =
      fs::temp_directory_path() / ("hapsim_golden_" + std::to_string(::getpid()) + ".rec");
  std::vector<RecordedFrame> frames;
  {
    SessionRecorder recorder(rec, world.content_hash(), 8192);
    SessionOptions options;
    options.duration_s = duration_s;
    options.dt_s = scene.run.dt_s;
    options.recorder = &recorder;
    (void)run_session(world, *device, options);
    recorder.close();
    frames = read_recording(rec).frames;
  }
  fs::remove(rec);

  test::GoldenTrace trace;
  trace.scene = name;
  trace.columns = {"force_x_n", "force_y_n", "force_z_n", "finger0_n",
                   "finger1_n", "finger2_n", "finger3_n", "finger4_n"};
  trace.cycle_count = frames.size();
  for (const RecordedFrame& f : frames) {
    test::GoldenCycle c;
    c.index = f.cycle_index;
    const DeviceCommand& cmd = f.command;
    c.values = {cmd.force_world_n.x(), cmd.force_world_n.y(), cmd.force_world_n.z()};
    for (int i = 0; i < kMaxFingers; ++i) {
      c.values.push_back(cmd.finger_force_n[static_cast<std::size_t>(i)]);
    }
    for (int i = 0; i < f.contact_count; ++i) {
      const RecordedContact& k = f.contacts[static_cast<std::size_t>(i)];
      c.contacts.push_back({k.tool_index, k.body_index, k.segment_index, k.force_n});
    }
    test::append_cycle(trace, std::move(c));
  }
  return trace;
}

// A teleoperation scene as `hapsim run` steps it inline: the master trajectory sampled at
// start + k·dt, the world's command straight to the master.
test::GoldenTrace run_teleop_scene(const SceneDescription& scene, const std::string& name) {
  TeleopSetup setup = make_teleop_setup(scene, std::nullopt, /*load_link_meshes=*/false);
  const Trajectory trajectory = setup.trajectory;
  World world(std::move(setup.description));
  const double dt = scene.run.dt_s;
  const double duration = scene.run.duration_s > 0.0
                              ? scene.run.duration_s
                              : trajectory.end_time_s() - trajectory.start_time_s();
  const auto steps = static_cast<std::size_t>(std::llround(duration / dt));
  test::GoldenTrace trace;
  trace.scene = name;
  trace.columns = {"torque0_nm",   "torque1_nm",   "torque2_nm",  "torque3_nm", "torque4_nm",
                   "finger0_n",    "finger1_n",    "pad0_n",      "pad1_n",     "sheet_x_n",
                   "sheet_y_n",    "sheet_z_n",    "floor_x_n",   "floor_y_n",  "floor_z_n",
                   "ball_x_m",     "ball_y_m",     "ball_z_m",    "held",       "sheet_depth_m",
                   "slave_tool_x", "slave_tool_y", "slave_tool_z"};
  trace.cycle_count = steps;
  for (std::size_t k = 1; k <= steps; ++k) {
    const DeviceInput in =
        trajectory.sample_at(trajectory.start_time_s() + static_cast<double>(k) * dt);
    const TeleopStepResult& r = *world.step(in, dt).teleop;
    test::GoldenCycle c;
    c.index = k - 1;
    for (std::size_t i = 0; i < 5; ++i) {
      c.values.push_back(r.command.joint_torque_nm[i]);
    }
    c.values.push_back(r.command.finger_force_n[0]);
    c.values.push_back(r.command.finger_force_n[1]);
    c.values.push_back(r.gripper.pad_force_n[0]);
    c.values.push_back(r.gripper.pad_force_n[1]);
    for (int i = 0; i < 3; ++i) {
      c.values.push_back(r.ball_contacts.sheet_force_world_n[i]);
    }
    for (int i = 0; i < 3; ++i) {
      c.values.push_back(r.ball_contacts.floor_force_world_n[i]);
    }
    for (int i = 0; i < 3; ++i) {
      c.values.push_back(r.ball_p_world[i]);
    }
    c.values.push_back(r.held ? 1.0 : 0.0);
    c.values.push_back(r.sheet_depth_m);
    for (int i = 0; i < 3; ++i) {
      c.values.push_back(r.slave_tool.translation()[i]);
    }
    test::append_cycle(trace, std::move(c));
  }
  return trace;
}

void check_scene(const std::string& name, const std::string& data_folder = {}) {
  const auto options = load_options(data_folder);
  if (!options) {
    GTEST_SKIP() << "real data '" << data_folder << "' not found under " << HAPSIM_TEST_DATA_DIR
                 << " (tests with real data skip)";
  }
  const SceneDescription scene = load_scene(kScenes / (name + ".json"), *options);
  const test::GoldenTrace actual =
      scene.is_teleop ? run_teleop_scene(scene, name) : run_world_scene(scene, name);
  const fs::path golden = kGolden / (name + ".trace.gz");
  const char* update = std::getenv("HAPSIM_UPDATE_GOLDEN");
  if (update != nullptr && std::string(update) == "1") {
    test::write_golden(golden, actual);
    GTEST_SKIP() << "re-recorded " << golden;
  }
  ASSERT_TRUE(fs::exists(golden)) << golden << " missing (HAPSIM_UPDATE_GOLDEN=1 records it)";
  const test::GoldenTrace expected = test::read_golden(golden);
  ASSERT_GT(expected.cycles.size(), 0U);
  const std::string difference = test::compare_golden(expected, actual, kTolerance);
  EXPECT_TRUE(difference.empty()) << name << " differs from " << golden << ": " << difference;
}

TEST(GoldenRun, Knee) {
  check_scene("knee");
}
TEST(GoldenRun, KneeHand) {
  check_scene("knee_hand");
}
TEST(GoldenRun, Teleop) {
  check_scene("teleop");
}
TEST(GoldenRun, TeleopGp7) {
  check_scene("teleop_gp7", "motoman_gp7");
}
TEST(GoldenRun, KneeVhf) {
  check_scene("knee_vhf", "knee_vhf_left");
}

// The comparison itself must be able to fail: a changed force, a missing contact and a moved
// contact are each found.
TEST(GoldenRun, ComparisonFindsDifferences) {
  test::GoldenTrace a;
  a.columns = {"f"};
  a.cycle_count = 3;
  a.cycles.push_back({1, {0.5}, {{0, 0, 2, 0.5}}});
  test::GoldenTrace b = a;
  EXPECT_EQ(test::compare_golden(a, b, kTolerance), "");
  b.cycles[0].values[0] = 0.5 + 1e-8;
  EXPECT_NE(test::compare_golden(a, b, kTolerance).find("cycle 1, f"), std::string::npos);
  b = a;
  b.cycles[0].contacts[0].segment = 3;
  EXPECT_NE(test::compare_golden(a, b, kTolerance).find("missing"), std::string::npos);
  b = a;
  b.cycles[0].index = 2;
  EXPECT_NE(test::compare_golden(a, b, kTolerance), "");
  const fs::path file = fs::temp_directory_path() /
                        ("hapsim_golden_roundtrip_" + std::to_string(::getpid()) + ".trace.gz");
  test::write_golden(file, a);
  EXPECT_EQ(test::compare_golden(a, test::read_golden(file), 0.0), "");
  fs::remove(file);
}

}  // namespace
}  // namespace hapsim
