// The mixed scene (scenes/hand_ball_sheet.json) as `hapsim run` runs it: the glove hand pinches the
// ball off the table, lifts it, presses it into the sheet and lets go; the ball must end at rest on
// the sheet, where the analytic rest height puts it (the sheet's Gaussian dent under the ball's
// weight plus the contact spring's give, both materials in series), having been lifted by the
// fingers alone; the run records and replays bit for bit; the loader refuses bad dynamic and sheet
// bodies by JSON pointer.
#include "hapsim/core/error.h"
#include "hapsim/deform/sheet_profile.h"
#include "hapsim/device/recording.h"
#include "hapsim/runtime/session.h"
#include "hapsim/scene/run_setup.h"
#include "hapsim/scene/scene_file.h"

#include "support/replay_check.h"
#include "support/temp_path.h"

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <filesystem>
#include <fstream>
#include <functional>
#include <vector>

namespace hapsim {
namespace {

namespace fs = std::filesystem;
const fs::path kScene = fs::path(HAPSIM_SOURCE_DIR) / "scenes" / "hand_ball_sheet.json";

TEST(HandBallSheet, TheHandLiftsTheBallAndItEndsAtRestOnTheSheet) {
  RunSetup setup = make_run_setup(load_scene(kScene), DeviceChoice::scene_script());
  SessionOptions options;
  options.duration_s = setup.duration_s;
  options.dt_s = setup.scene.run.dt_s;
  const SessionSummary s = run_session(*setup.world, *setup.device, options);
  ASSERT_EQ(s.bodies.size(), 1U);
  ASSERT_EQ(s.sheets.size(), 1U);
  const BodySummary& ball = s.bodies.front();
  EXPECT_EQ(ball.nonfinite_steps, 0U);
  EXPECT_EQ(ball.touching_at_end, std::vector<std::string>{"sheet"});
  EXPECT_LT(ball.final_speed_m_per_s, 2e-3) << "at rest";
  // Carried by the fingers: it rose above the sheet (50 mm higher than the table) on the way.
  EXPECT_GT(ball.max_rise_m, 0.05 + 0.04);
  // Where the script put it: over the sheet's centre (the sheet at (0.12, 0, 0.05)).
  EXPECT_NEAR(ball.final_world.x(), 0.12, 0.003);
  EXPECT_NEAR(ball.final_world.y(), 0.0, 0.003);
  // At rest its weight is carried by the sheet: the elastic field sinks by the Gaussian profile of
  // m·g (F0 = 0.5 N/mm, d0 = 44 mm, ξ = 40.1 mm) and the ball presses m·g / k into it, k the ball's
  // and the sheet's contact springs in series (2000 and 800 N/m).
  const double weight_n = 0.1 * 9.81;
  const double sink_m =
      GaussianSheetProfile(GaussianSheetParams::from_mm(44.0, 40.1, 0.5)).depth_m(0.0, weight_n);
  const double give_m = weight_n / (2000.0 * 800.0 / 2800.0);
  EXPECT_NEAR(ball.final_world.z(), 0.05 + 0.03 - sink_m - give_m, 2e-4);
  // The sheet was pressed deeper while the hand pushed, and keeps the ball's imprint after.
  const SheetSummary& sheet = s.sheets.front();
  EXPECT_GT(sheet.max_depth_m, 2.0 * sheet.final_depth_m);
  EXPECT_GT(sheet.final_depth_m, sink_m);
  EXPECT_LE(sheet.final_depth_m, sink_m + give_m + 1e-9);
  // The fingers felt the pinch (rendered on the glove's thumb and index actuators).
  ASSERT_EQ(s.tools.size(), 2U);
  EXPECT_GT(s.tools[0].peak_force_n, 1.0);
  EXPECT_GT(s.tools[1].peak_force_n, 1.0);
  EXPECT_EQ(s.pop_throughs, 0U);
  EXPECT_EQ(s.max_force_limit_violations, 0U);
}

TEST(HandBallSheet, RecordsAndReplaysBitForBit) {
  const fs::path recording = test::temp_path(".rec");
  RunSetup setup = make_run_setup(load_scene(kScene), DeviceChoice::scene_script());
  test::record_run(setup, recording);
  EXPECT_TRUE(test::replays_bit_for_bit(load_scene(kScene), recording));
  fs::remove(recording);
}

// A replay runs the recording's length, not the scene's run.duration_s: a 0.5 s recording of a
// scene that says 3 s replays (bit for bit) in 0.5 s.
TEST(HandBallSheet, AReplayRunsTheRecordingsLengthNotTheScenes) {
  nlohmann::json j = nlohmann::json::parse(std::ifstream(kScene));
  j["run"]["duration_s"] = 3.0;
  const SceneDescription scene = parse_scene(j.dump(), kScene);
  const fs::path recording = test::temp_path(".rec");
  RunSetup setup = make_run_setup(scene, DeviceChoice::scene_script());
  EXPECT_DOUBLE_EQ(setup.duration_s, 3.0);
  test::record_run(setup, recording, 0.5);
  EXPECT_NEAR(make_run_setup(scene, DeviceChoice::replay(recording)).duration_s, 0.5, 1e-9);
  EXPECT_TRUE(test::replays_bit_for_bit(scene, recording));
  fs::remove(recording);
}

// A dynamic body of any closed shape from a scene file: its inertia is the solid's at uniform
// density (a box's m·(b² + c²)/3 about x for half extents a, b, c), and dropped on the table it
// comes to rest on its four bottom corners, each a spring of both materials in series carrying a
// quarter of its weight, while the hand works beside it. The same block in rubber is refused: its
// four corners pressing the sheet together would not settle.
TEST(HandBallSheet, ADynamicBoxFromTheSceneFileRestsOnTheTable) {
  nlohmann::json j = nlohmann::json::parse(std::ifstream(kScene));
  const double a = 0.02;
  const double b = 0.015;
  const double c = 0.01;
  const double mass = 0.2;
  j["bodies"].push_back({{"name", "block"},
                         {"type", "dynamic"},
                         {"mass_kg", mass},
                         {"pose", {{"position_m", {0.0, 0.12, c + 0.01}}}},
                         {"geometry", {{"box", {{"half_extents_m", {a, b, c}}}}}},
                         {"materials", {{"default", "foam"}}}});
  // A foam block: any dynamic body may come to press the sheet, and a box presses it with its
  // four corners together, so its material must be soft enough for that press to settle (a
  // rubber block, 2000 N/m, is refused at load: it would ring on the sheet).
  j["materials"]["foam"] = {{"response", "penalty"},     {"stiffness_n_per_m", 400.0},
                            {"max_penetration_m", 0.01}, {"max_force_n", 10.0},
                            {"damping_n_s_per_m", 2.0},  {"static_friction", 0.8},
                            {"dynamic_friction", 0.6}};
  j["run"]["duration_s"] = 2.0;
  const SceneDescription scene = parse_scene(j.dump(), kScene);
  const BodyDescription& block = scene.world.bodies.back();
  EXPECT_NEAR(block.rigid.inertia_kg_m2(0, 0), mass * (b * b + c * c) / 3.0, 1e-12);
  EXPECT_NEAR(block.rigid.inertia_kg_m2(2, 2), mass * (a * a + b * b) / 3.0, 1e-12);
  EXPECT_NEAR(block.rigid.inertia_kg_m2(0, 1), 0.0, 1e-12);
  RunSetup setup = make_run_setup(scene, DeviceChoice::scene_script());
  SessionOptions options;
  options.duration_s = setup.duration_s;
  options.dt_s = setup.scene.run.dt_s;
  const SessionSummary s = run_session(*setup.world, *setup.device, options);
  ASSERT_EQ(s.bodies.size(), 2U);
  const BodySummary& box = s.bodies.back();
  EXPECT_EQ(box.name, "block");
  EXPECT_EQ(box.nonfinite_steps, 0U);
  EXPECT_EQ(box.touching_at_end, std::vector<std::string>{"table"});
  EXPECT_LT(box.final_speed_m_per_s, 1e-4);
  const double k = 400.0 * 20000.0 / 20400.0;  // foam and table materials in series
  EXPECT_NEAR(box.final_world.z(), c - mass * 9.81 / (4.0 * k), 2e-6);
  EXPECT_NEAR(box.final_world.x(), 0.0, 1e-6);
  EXPECT_NEAR(box.final_world.y(), 0.12, 1e-6);

  j["bodies"].back()["materials"]["default"] = "ball";
  try {
    (void)make_run_setup(parse_scene(j.dump(), kScene), DeviceChoice::scene_script());
    ADD_FAILURE() << "a rubber block that cannot settle on the sheet was accepted";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("body 'block' presses the sheet"), std::string::npos)
        << e.what();
  }
}

// Bad dynamic and sheet bodies are refused by the loader, each naming its place.
TEST(HandBallSheet, BadBodiesAreRefusedByPointer) {
  const nlohmann::json base = nlohmann::json::parse(std::ifstream(kScene));
  struct Case {
    const char* what;
    std::function<void(nlohmann::json&)> edit;
    const char* expected;
  };
  const std::vector<Case> cases = {
      {"dynamic without mass", [](nlohmann::json& j) { j["bodies"][1].erase("mass_kg"); },
       "/bodies/1"},
      {"mass on a static body", [](nlohmann::json& j) { j["bodies"][0]["mass_kg"] = 1.0; },
       "/bodies/0/mass_kg"},
      {"zero mass", [](nlohmann::json& j) { j["bodies"][1]["mass_kg"] = 0.0; },
       "/bodies/1/mass_kg"},
      {"sheet deformation on a box",
       [](nlohmann::json& j) {
         j["bodies"][2]["geometry"] = {{"box", {{"half_extents_m", {0.1, 0.1, 0.01}}}}};
       },
       "/bodies/2/geometry"},
      {"sheet settings without the sheet deformation",
       [](nlohmann::json& j) { j["bodies"][2].erase("deformation"); }, "/bodies/2/sheet"},
      {"deformation on a static body",
       [](nlohmann::json& j) { j["bodies"][0]["deformation"] = "sheet"; }, "/bodies/0/deformation"},
      {"unknown ball", [](nlohmann::json& j) { j["device"]["glove_pick_and_place"]["ball"] = "x"; },
       "/device/glove_pick_and_place/ball"},
      {"no index tool", [](nlohmann::json& j) { j["tools"].erase(1); },
       "/device/glove_pick_and_place"},
      {"gravity not a vector", [](nlohmann::json& j) { j["world"]["gravity_m_per_s2"] = 9.81; },
       "/world/gravity_m_per_s2"},
  };
  for (const Case& c : cases) {
    nlohmann::json j = base;
    c.edit(j);
    try {
      (void)parse_scene(j.dump(), kScene);
      ADD_FAILURE() << c.what << ": loaded";
    } catch (const Error& e) {
      EXPECT_NE(std::string(e.what()).find(c.expected), std::string::npos)
          << c.what << ": " << e.what();
    }
  }
}

// A sheet whose contact spring is stiffer than the sheet itself would never settle: the world
// refuses it at build, naming the sheet and both stiffnesses.
TEST(HandBallSheet, ASheetStifferContactThanTheSheetIsRefused) {
  nlohmann::json j = nlohmann::json::parse(std::ifstream(kScene));
  j["bodies"][2]["sheet"]["sensitivity_n_per_mm"] = 0.1;  // 0.1 N/mm: ~140 N/m under a press
  try {
    (void)make_run_setup(parse_scene(j.dump(), kScene), DeviceChoice::scene_script());
    ADD_FAILURE() << "built";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("body 'sheet'"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("not softer than the sheet"), std::string::npos)
        << e.what();
  }
}

}  // namespace
}  // namespace hapsim
