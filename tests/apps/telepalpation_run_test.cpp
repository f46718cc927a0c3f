// `hapsim run scenes/telepalpation.json` as a user runs it: a rig scene with a knee body runs
// from the scene file, says what the slave's tool felt, draws the pad on the knee, and its
// recording replays bit for bit and is scored against its landmarks.
#include "hapsim_process.h"

#include <nlohmann/json.hpp>

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <string>

namespace {

using hapsim::test::run_hapsim;
using hapsim::test::RunResult;
using hapsim::test::temp_path;

const std::string kScene = std::string(HAPSIM_SCENES_DIR) + "/telepalpation.json";

TEST(TelepalpationRun, RunsRecordsAndReplaysBitForBit) {
  const auto json_path = temp_path("telepalpation.json");
  const auto rec = temp_path("telepalpation.rec");
  const auto png = temp_path("telepalpation.png");
  const RunResult r =
      run_hapsim("run " + kScene + " -q --json " + json_path.string() + " --record " +
                 rec.string() + " --snapshot " + png.string() + " --view pad --size 320x180");
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_NE(r.output.find("carrying tool 'pad'"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("slave tool   peak force"), std::string::npos) << r.output;
  EXPECT_EQ(r.output.find("grasp "), std::string::npos) << "no ball, no grasp line\n" << r.output;
  {
    std::ifstream in(json_path);
    const nlohmann::json j = nlohmann::json::parse(in);
    EXPECT_TRUE(j.at("ok").get<bool>());
    EXPECT_GT(j.at("peak_tool_force_n").get<double>(), 2.0);
    EXPECT_LT(j.at("peak_tool_force_n").get<double>(), 30.0);
    EXPECT_GT(j.at("peak_master_torque_nm").get<double>(), 0.1);
    EXPECT_EQ(j.at("pop_throughs").get<int>(), 0);
  }
  EXPECT_GT(std::filesystem::file_size(png), 1000U);

  const auto again_json = temp_path("telepalpation_replay.json");
  const RunResult again = run_hapsim("run " + kScene + " -q --replay " + rec.string() + " --json " +
                                     again_json.string());
  ASSERT_EQ(again.exit_code, 0) << again.output;
  std::ifstream in(again_json);
  const nlohmann::json j = nlohmann::json::parse(in);
  EXPECT_TRUE(j.at("replay_identical").get<bool>()) << again.output;
  EXPECT_GT(j.at("steps").get<int>(), 9000);

  // Scored as a palpation through the slave: the carried pad's contacts find the landmarks.
  const auto assessed = temp_path("telepalpation_assessment.json");
  const RunResult scored =
      run_hapsim("assess " + rec.string() + " --scene " + kScene + " --json " + assessed.string());
  ASSERT_EQ(scored.exit_code, 0) << scored.output;
  std::ifstream a(assessed);
  const nlohmann::json result = nlohmann::json::parse(a);
  EXPECT_EQ(result.at("kind").get<std::string>(), "palpation") << result.dump(2);
  EXPECT_NE(scored.output.find("3 of 3 found"), std::string::npos) << scored.output;
}

}  // namespace
