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
#include "hapsim/rig/rig_controller.h"
#include "hapsim/runtime/session.h"
#include "hapsim/scene/run_setup.h"
#include "hapsim/scene/scene_file.h"
#include "hapsim/world/world.h"
#include "support/test_data.h"

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
  const auto root = test::data_dir();
  if (!root || !fs::is_directory(*root / data_folder)) {
    return std::nullopt;
  }
  o.data_dir = *root / data_folder;
  return o;
}

// A scene as `hapsim run` runs it: assembled by make_run_setup (the world no stiffer than the
// device's rating, the scene's scripted device), stepped by run_session with the safety layer,
// every cycle recorded; for a teleoperation rig also the rig's own step after each cycle.
test::GoldenTrace run_scene(SceneDescription scene, const std::string& name) {
  RunSetup setup = make_run_setup(std::move(scene), DeviceChoice::scene_script());
  World& world = *setup.world;
  const fs::path rec =
      fs::temp_directory_path() / ("hapsim_golden_" + std::to_string(::getpid()) + ".rec");
  std::vector<TeleopStepResult> rig_steps;
  std::vector<RecordedFrame> frames;
  {
    SessionRecorder recorder(rec, world.content_hash(), 8192);
    SessionOptions options;
    options.duration_s = setup.duration_s;
    options.dt_s = setup.scene.run.dt_s;
    options.recorder = &recorder;
    if (rig_state(world) != nullptr) {
      options.after_cycle = [&](std::size_t) { rig_steps.push_back(rig_state(world)->result); };
    }
    (void)run_session(world, *setup.device, options);
    recorder.close();
    frames = read_recording(rec).frames;
  }
  fs::remove(rec);

  test::GoldenTrace trace;
  trace.scene = name;
  trace.cycle_count = frames.size();
  if (rig_state(world) == nullptr) {
    trace.columns = {"force_x_n", "force_y_n", "force_z_n", "finger0_n",
                     "finger1_n", "finger2_n", "finger3_n", "finger4_n"};
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
  // The rig: the world's own step (torques before the safety layer, pads, sheet, floor, ball).
  trace.columns = {"torque0_nm",   "torque1_nm",   "torque2_nm",  "torque3_nm", "torque4_nm",
                   "finger0_n",    "finger1_n",    "pad0_n",      "pad1_n",     "sheet_x_n",
                   "sheet_y_n",    "sheet_z_n",    "floor_x_n",   "floor_y_n",  "floor_z_n",
                   "ball_x_m",     "ball_y_m",     "ball_z_m",    "held",       "sheet_depth_m",
                   "slave_tool_x", "slave_tool_y", "slave_tool_z"};
  for (std::size_t k = 0; k < rig_steps.size(); ++k) {
    const TeleopStepResult& r = rig_steps[k];
    test::GoldenCycle c;
    c.index = k;
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
  HAPSIM_SKIP_WITHOUT_DATA(options.has_value(), "real data '" << data_folder << "' not found");
  const test::GoldenTrace actual =
      run_scene(load_scene(kScenes / (name + ".json"), *options), name);
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

// The procedural knee (its golden recorded before the real knee became the default scene).
TEST(GoldenRun, KneeProcedural) {
  check_scene("knee_procedural");
}
// The paper's model of the real Visible Human knee (committed meshes, no data folder needed):
// the default scene until 2026-11-27, its golden recorded then and renamed with the scene.
TEST(GoldenRun, KneePaper) {
  check_scene("knee_paper");
}
// The default scene since 2026-11-27: the FEM knee (recorded when it became the default; the FEM
// updates run inline at launch + one period, so the run is a function of the script).
TEST(GoldenRun, Knee) {
  check_scene("knee");
}
TEST(GoldenRun, KneeHand) {
  check_scene("knee_hand_procedural");
}
// Recorded 2026-11-26, after the one-world refactor (these scenes came later): they hold what
// the scenes do now against later changes. The glove's index on the paper's real knee model.
TEST(GoldenRun, KneeHandPaper) {
  check_scene("knee_hand_paper");
}
// The glove's index and middle fingers on the FEM knee's vastus medialis (recorded 2026-11-27).
TEST(GoldenRun, KneeHandReal) {
  check_scene("knee_hand");
}
// The glove pinching a dynamic ball above the virtual sheet.
TEST(GoldenRun, HandBallSheet) {
  check_scene("hand_ball_sheet");
}
// A CSG block palpated through the god object.
TEST(GoldenRun, CsgBlock) {
  check_scene("csg_block");
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
