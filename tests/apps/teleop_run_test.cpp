// `hapsim run scenes/teleop.json` as a user runs it: the unattended pick-and-place completes
// (grasped, released, the ball on the sheet within 5 mm of the target), the summary and the JSON
// hold what the issue lists, the GP7 variant runs when its URDF is there, and options a teleop
// scene cannot honour are refused with one line.
#include "hapsim_process.h"
#include "support/test_data.h"

#include <nlohmann/json.hpp>

#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <string>

namespace {

using hapsim::test::run_hapsim;
using hapsim::test::RunResult;
using hapsim::test::temp_path;

const std::string kScenes = HAPSIM_SCENES_DIR;

void expect_pick_and_place(const std::string& args, const std::string& json_name) {
  const auto json_path = temp_path(json_name);
  const RunResult r = run_hapsim(args + " -q --json " + json_path.string());
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_NE(r.output.find("grasp        achieved at"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("from the target spot"), std::string::npos) << r.output;
  std::ifstream in(json_path);
  const nlohmann::json j = nlohmann::json::parse(in);
  EXPECT_TRUE(j.at("grasped").get<bool>());
  const double grasp = j.at("grasp_time_s").get<double>();
  EXPECT_GT(j.at("release_time_s").get<double>(), grasp);
  EXPECT_GT(j.at("ball_lift_m").get<double>(), 0.1);
  ASSERT_EQ(j.at("ball_final_position_m").size(), 3u);
  EXPECT_LT(j.at("ball_target_error_m").get<double>(), 0.005);
  EXPECT_GT(j.at("peak_grasp_force_n").get<double>(), 1.0);
  EXPECT_GT(j.at("max_sheet_deflection_m").get<double>(), 1e-4);
  for (const char* k : {"p50", "p99", "max"}) {
    EXPECT_GT(j.at("step_us").at(k).get<double>(), 0.0) << k;
  }
  EXPECT_TRUE(j.at("ok").get<bool>());
}

TEST(TeleopRun, PickAndPlaceCompletesUnattended) {
  expect_pick_and_place("run " + kScenes + "/teleop.json", "teleop.json");
}

TEST(TeleopRun, Gp7VariantRunsWhenTheDataIsThere) {
  const auto data = hapsim::test::data_path("motoman_gp7");
  HAPSIM_SKIP_WITHOUT_DATA(std::filesystem::exists(data / "gp7.urdf"),
                           "Motoman GP7 URDF not found in " << data);
  expect_pick_and_place("run " + kScenes + "/teleop_gp7.json --data " + data.string(),
                        "teleop_gp7.json");
}

// A teleoperation run goes through the same run path as the knee: recorded, it replays bit for bit
// (every cycle's master input and the torques sent after the safety layer).
TEST(TeleopRun, RecordingReplaysBitForBit) {
  const auto rec = temp_path("teleop.rec");
  const RunResult r = run_hapsim("run " + kScenes + "/teleop.json -q --record " + rec.string());
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_NE(r.output.find("recorded     "), std::string::npos) << r.output;
  const auto json_path = temp_path("teleop_replay.json");
  const RunResult again = run_hapsim("run " + kScenes + "/teleop.json -q --replay " + rec.string() +
                                     " --json " + json_path.string());
  ASSERT_EQ(again.exit_code, 0) << again.output;
  EXPECT_NE(again.output.find("identical to"), std::string::npos) << again.output;
  std::ifstream in(json_path);
  const nlohmann::json j = nlohmann::json::parse(in);
  EXPECT_TRUE(j.at("replay_identical").get<bool>());
  EXPECT_GT(j.at("steps").get<int>(), 5000);
  // The replayed rig placed the ball as the scripted run did.
  EXPECT_TRUE(j.at("grasped").get<bool>());
  // A recording of the knee is not a recording of the teleop scene.
  const auto knee_rec = temp_path("knee.rec");
  ASSERT_EQ(run_hapsim("run " + kScenes + "/knee_procedural.json -q --duration 0.05 --record " +
                       knee_rec.string())
                .exit_code,
            0);
  const RunResult wrong =
      run_hapsim("run " + kScenes + "/teleop.json -q --replay " + knee_rec.string());
  EXPECT_EQ(wrong.exit_code, 2) << wrong.output;
  EXPECT_NE(wrong.output.find("different scene"), std::string::npos) << wrong.output;
}

TEST(TeleopRun, UnsupportedOptionsAreOneLine) {
  for (const std::string opt :
       {"--realtime --snapshot-every 10 --snapshot /tmp/x.png", "--duration -1"}) {
    SCOPED_TRACE(opt);
    const RunResult r = run_hapsim("run " + kScenes + "/teleop.json -q " + opt);
    EXPECT_EQ(r.exit_code, 2) << r.output;
    EXPECT_EQ(std::count(r.output.begin(), r.output.end(), '\n'), 1) << r.output;
  }
}

}  // namespace
