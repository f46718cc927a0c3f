// `hapsim run` on the real-time loop and with offscreen snapshots, through the real binary: the
// JSON realtime block, pictures written with no display (sized as asked, not blank, numbered
// series), and bad snapshot options as one named line with exit status 2.
#include "hapsim_process.h"

#include "hapsim/render/png_image.h"

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <algorithm>
#include <fstream>

namespace hapsim {
namespace {

const std::string kKnee = std::string(HAPSIM_SCENES_DIR) + "/knee_procedural.json";

TEST(RunCommand, RealtimeAddsTheLoopFiguresToTheSummary) {
  const auto json = test::temp_path("rt.json");
  const auto r =
      test::run_hapsim("run " + kKnee + " -q --realtime --duration 0.5 --json " + json.string());
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_NE(r.output.find("real time:"), std::string::npos) << r.output;
  std::ifstream in(json);
  const nlohmann::json j = nlohmann::json::parse(in);
  ASSERT_TRUE(j.contains("realtime")) << j.dump(2);
  const auto& rt = j["realtime"];
  EXPECT_GT(rt["rate_hz"].get<double>(), 0.0);
  EXPECT_LE(rt["period_jitter_us"]["p50"].get<double>(),
            rt["period_jitter_us"]["p99"].get<double>());
  EXPECT_LE(rt["period_jitter_us"]["p99"].get<double>(),
            rt["period_jitter_us"]["max"].get<double>());
  EXPECT_TRUE(rt.contains("missed_deadlines"));
  EXPECT_EQ(j["steps"].get<int>() + rt["dropped_records"].get<int>(), 500);
  // The loop's own count of cycles, and the share of them capped for lateness alone. 500 cycles
  // are too few for the sentence that says the rate cannot be kept, however slow the machine.
  EXPECT_EQ(rt["cycles"].get<int>(), 500);
  EXPECT_LE(rt["late_ramp_cycles"].get<int>(), rt["ramp_cycles"].get<int>());
  EXPECT_NEAR(rt["late_ramp_share"].get<double>(), rt["late_ramp_cycles"].get<double>() / 500.0,
              1e-12);
  EXPECT_FALSE(rt.contains("warning")) << rt.dump(2);
  EXPECT_EQ(j["pop_throughs"].get<int>(), 0);
}

TEST(RunCommand, SnapshotsAreWrittenWithNoDisplay) {
  const auto png = test::temp_path("knee.png");
  const auto r = test::run_hapsim("run " + kKnee + " -q --duration 0.6 --snapshot " + png.string() +
                                  " --snapshot-every 200 --size 400x300 " + "--display-mode lines");
  ASSERT_EQ(r.exit_code, 0) << r.output;
  const RgbaImage image = read_png(png.string());
  EXPECT_EQ(image.width, 400);
  EXPECT_EQ(image.height, 300);
  // Not a blank frame: the knee's lines differ from the background corner.
  int differing = 0;
  for (std::size_t i = 0; i < image.rgba.size(); i += 4) {
    differing += image.rgba[i] != image.rgba[0] ? 1 : 0;
  }
  EXPECT_GT(differing, 400 * 300 / 20);
  for (const char* n : {"knee_000200.png", "knee_000400.png", "knee_000600.png"}) {
    EXPECT_TRUE(std::filesystem::exists(test::temp_path(n))) << n;
  }
}

TEST(RunCommand, BadSnapshotOptionsAreNamed) {
  auto r = test::run_hapsim("run " + kKnee + " --duration 0.1 --snapshot /tmp/x.png --size 12x");
  EXPECT_EQ(r.exit_code, 2) << r.output;
  EXPECT_NE(r.output.find("--size"), std::string::npos) << r.output;
  r = test::run_hapsim("run " + kKnee +
                       " --duration 0.1 --realtime --snapshot /tmp/x.png --snapshot-every 10");
  EXPECT_EQ(r.exit_code, 2) << r.output;
  EXPECT_NE(r.output.find("--snapshot-every"), std::string::npos) << r.output;
  r = test::run_hapsim("run " + kKnee + " --duration 0.1 --snapshot /nonexistent/dir/x.png");
  EXPECT_EQ(r.exit_code, 2) << r.output;
  EXPECT_NE(r.output.find("/nonexistent/dir/x.png"), std::string::npos) << r.output;
  r = test::run_hapsim("run " + kKnee + " --duration 0.1 --snapshot /tmp/x.png --display-mode x");
  EXPECT_NE(r.exit_code, 0) << r.output;
}

TEST(RunCommand, BadCameraOptionsAreOneNamedLine) {
  const std::string hand = std::string(HAPSIM_SCENES_DIR) + "/knee_hand_procedural.json";
  const auto one_line = [](const std::string& out) {
    return std::count(out.begin(), out.end(), '\n') <= 1;
  };
  auto r = test::run_hapsim("run " + hand + " -q --duration 0.1 --snapshot /tmp/x.png --view nope");
  EXPECT_EQ(r.exit_code, 2) << r.output;
  EXPECT_NE(r.output.find("--view nope"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("fig6"), std::string::npos) << r.output;  // the views it has
  EXPECT_TRUE(one_line(r.output)) << r.output;
  for (const char* spec : {"1,2,3", "0,0,1,0,0,0,500", "0,0,1,0,0,1,40", "0,0,1,0,0,0,x"}) {
    r = test::run_hapsim("run " + hand + " -q --duration 0.1 --snapshot /tmp/x.png --camera " +
                         spec);
    EXPECT_EQ(r.exit_code, 2) << spec << ": " << r.output;
    EXPECT_NE(r.output.find("--camera"), std::string::npos) << r.output;
    EXPECT_TRUE(one_line(r.output)) << r.output;
  }
  r = test::run_hapsim(
      "run " + hand +
      " -q --duration 0.1 --snapshot /tmp/x.png --view fig6 --camera 0,0,1,0,0,0,40");
  EXPECT_EQ(r.exit_code, 2) << r.output;
  r = test::run_hapsim("run " + hand + " -q --duration 0.1 --snapshot /tmp/x.png --stereo 3d");
  EXPECT_EQ(r.exit_code, 2) << r.output;
  EXPECT_NE(r.output.find("--stereo"), std::string::npos) << r.output;
  EXPECT_TRUE(one_line(r.output)) << r.output;
  r = test::run_hapsim("run " + hand +
                       " -q --duration 0.1 --snapshot /tmp/x.png --stereo anaglyph "
                       "--eye-separation -1");
  EXPECT_NE(r.exit_code, 0) << r.output;
  EXPECT_NE(r.output.find("--eye-separation"), std::string::npos) << r.output;
  r = test::run_hapsim("run " + hand + " -q --duration 0.1 --view fig6");
  EXPECT_EQ(r.exit_code, 2) << r.output;
  EXPECT_NE(r.output.find("--snapshot"), std::string::npos) << r.output;
}

TEST(RunCommand, NamedViewAndCameraGiveTheSamePicture) {
  // fig6 in scenes/knee_hand_procedural.json, written out as --camera: the same picture.
  const std::string hand = std::string(HAPSIM_SCENES_DIR) + "/knee_hand_procedural.json";
  const auto a = test::temp_path("view.png");
  const auto b = test::temp_path("camera.png");
  const auto c = test::temp_path("default.png");
  ASSERT_EQ(test::run_hapsim("run " + hand + " -q --duration 1 --size 320x180 --snapshot " +
                             a.string() + " --view fig6")
                .exit_code,
            0);
  ASSERT_EQ(test::run_hapsim("run " + hand + " -q --duration 1 --size 320x180 --snapshot " +
                             b.string() + " --camera -0.25,0.3,0.12,0,0.06,0.02,40")
                .exit_code,
            0);
  ASSERT_EQ(
      test::run_hapsim("run " + hand + " -q --duration 1 --size 320x180 --snapshot " + c.string())
          .exit_code,
      0);
  EXPECT_EQ(read_png(a.string()).rgba, read_png(b.string()).rgba);
  EXPECT_NE(read_png(a.string()).rgba, read_png(c.string()).rgba);
}

}  // namespace
}  // namespace hapsim

namespace hapsim {
namespace {

// The pick-and-place on the real-time haptic thread places the ball as the inline run does
// (the simulated master plays by simulation time; every cycle is accounted through the ring).
TEST(RunCommand, TeleopRealtimePlacesTheBallAndReportsTheLoop) {
  const auto json = test::temp_path("teleop_rt.json");
  const auto r = test::run_hapsim("run " + std::string(HAPSIM_SCENES_DIR) +
                                  "/teleop.json -q --realtime --json " + json.string());
  ASSERT_EQ(r.exit_code, 0) << r.output;
  std::ifstream in(json);
  const nlohmann::json j = nlohmann::json::parse(in);
  EXPECT_TRUE(j["ok"].get<bool>());
  EXPECT_LT(j["ball_target_error_m"].get<double>(), 0.005);
  ASSERT_TRUE(j.contains("realtime")) << j.dump(2);
  EXPECT_GT(j["realtime"]["rate_hz"].get<double>(), 0.0);
  EXPECT_EQ(j["realtime"]["dropped_records"].get<int>(), 0);
}

}  // namespace
}  // namespace hapsim
