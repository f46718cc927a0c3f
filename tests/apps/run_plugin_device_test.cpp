// `hapsim run SCENE --device plugin:PATH.so`: a driver plugin's device drives the world on the
// real-time loop (the example driver, examples/device_plugin, pressing the CSG block's top face
// from its own frame), the summary and the JSON name it, the world renders no stiffer than the
// plugin's rating, and every wrong use is one named line with exit status 2. `hapsim view
// --device plugin:PATH.so` runs the viewer with it (under Xvfb): the window names the driver, the
// press reaches the block and the tool is drawn.
#include "hapsim_process.h"

#include "hapsim/render/png_image.h"

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <algorithm>
#include <cstdlib>
#include <fstream>
#include <iterator>
#include <string>

namespace hapsim {
namespace {

using test::run_hapsim;
using test::RunResult;
using test::temp_path;

bool contains(const std::string& text, const std::string& part) {
  return text.find(part) != std::string::npos;
}

const std::string kBlock = std::string(HAPSIM_SCENES_DIR) + "/csg_block.json";

#ifdef HAPSIM_EXAMPLE_DRIVER
// The example stylus circles 5 mm round the top face's centre, 3 mm above it (the tip's radius),
// and presses 3 mm down once a second.
const std::string kPlugin = std::string(" --device plugin:") + HAPSIM_EXAMPLE_DRIVER +
                            " --driver-config radius_m=0.005,center_z_m=0.018,press_depth_m=0.003";

TEST(RunPluginDevice, ThePluginDrivesTheWorldInRealTimeAndIsNamed) {
  const auto json_path = temp_path("run-plugin.json");
  const RunResult r =
      run_hapsim("run " + kBlock + kPlugin + " --duration 1.5 -q --json " + json_path.string());
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_TRUE(contains(r.output, "device       plugin 'example-circle-press' (" +
                                     std::string(HAPSIM_EXAMPLE_DRIVER) + ", rated 5.0 N"))
      << r.output;
  EXPECT_TRUE(contains(r.output, "in real time (a plugin's device runs on the real-time loop)"))
      << r.output;
  EXPECT_TRUE(contains(r.output, "plugin       'example-circle-press': ")) << r.output;
  // The block's plastic (1500 N/m) is rendered at the plugin's rating, not the scene's omega.3.
  EXPECT_TRUE(contains(r.output, "stiffness clamped to the device's rated 1000 N/m")) << r.output;

  std::ifstream in(json_path);
  const nlohmann::json j = nlohmann::json::parse(in);
  EXPECT_TRUE(contains(j.at("device").get<std::string>(), "plugin 'example-circle-press'"));
  const nlohmann::json& plugin = j.at("plugin");
  EXPECT_EQ(plugin.at("driver"), "example-circle-press");
  EXPECT_EQ(plugin.at("path"), HAPSIM_EXAMPLE_DRIVER);
  EXPECT_GE(plugin.at("reads").get<std::uint64_t>(), 1000u) << plugin.dump(2);
  EXPECT_EQ(plugin.at("bad_samples"), 0);
  EXPECT_EQ(plugin.at("health"), "connected");
  EXPECT_TRUE(j.contains("realtime")) << j.dump(2);
  // The press reached the block: contact, force, none above the plugin's 5 N.
  ASSERT_GE(j.at("tools").size(), 1u);
  EXPECT_GT(j.at("tools")[0].at("contact_steps").get<std::size_t>(), 100u) << j.dump(2);
  EXPECT_GT(j.at("tools")[0].at("peak_force_n").get<double>(), 0.5) << j.dump(2);
  EXPECT_LE(j.at("peak_command_force_n").get<double>(), 5.0 + 1e-9);
  EXPECT_EQ(j.at("max_force_limit_violations"), 0);
  EXPECT_EQ(j.at("pop_throughs"), 0);
}

TEST(RunPluginDevice, WrongUsesAreOneNamedLine) {
  const RunResult no_length = run_hapsim("run " + kBlock + kPlugin + " -q");
  EXPECT_EQ(no_length.exit_code, 2) << no_length.output;
  EXPECT_TRUE(contains(no_length.output, "give --duration S")) << no_length.output;

  const RunResult refused =
      run_hapsim("run " + kBlock + " --device plugin:" + HAPSIM_EXAMPLE_DRIVER +
                 " --driver-config colour=red --duration 1");
  EXPECT_EQ(refused.exit_code, 2) << refused.output;
  EXPECT_TRUE(contains(refused.output, "unknown key 'colour'")) << refused.output;

  const RunResult replay =
      run_hapsim("run " + kBlock + kPlugin + " --duration 1 --replay /tmp/x.rec");
  EXPECT_EQ(replay.exit_code, 2) << replay.output;
  EXPECT_TRUE(contains(replay.output, "give one")) << replay.output;

  const RunResult teleop = run_hapsim("run " + std::string(HAPSIM_SCENES_DIR) + "/teleop.json" +
                                      kPlugin + " --duration 1 -q");
  EXPECT_EQ(teleop.exit_code, 2) << teleop.output;
  EXPECT_TRUE(contains(teleop.output, "teleoperation scene")) << teleop.output;
}
#endif

TEST(RunPluginDevice, ABadPluginPathIsOneLineBeforeTheSceneLoads) {
  const RunResult r = run_hapsim("run " + kBlock + " --device plugin:/nonexistent/driver.so");
  EXPECT_EQ(r.exit_code, 2) << r.output;
  EXPECT_TRUE(contains(r.output, "hapsim: plugin /nonexistent/driver.so: no such file"))
      << r.output;
  EXPECT_FALSE(contains(r.output, "scene        ")) << r.output;

  const RunResult config = run_hapsim("run " + kBlock + " --driver-config x --duration 1");
  EXPECT_EQ(config.exit_code, 2) << config.output;
  EXPECT_TRUE(contains(config.output, "--driver-config: only with --device plugin:PATH.so"))
      << config.output;
}

TEST(RunPluginDevice, TheViewerRefusesABadPluginOrConfigBeforeAnyWindow) {
  // No display needed: these fail before the viewer opens one.
  const RunResult missing = test::run_hapsim_env(
      "env -u DISPLAY", "view " + kBlock + " --device plugin:/some/driver.so --duration 1");
  EXPECT_EQ(missing.exit_code, 2) << missing.output;
  EXPECT_TRUE(contains(missing.output, "hapsim: plugin /some/driver.so: no such file"))
      << missing.output;
  const RunResult config = run_hapsim("view " + kBlock + " --driver-config x --duration 1");
  EXPECT_EQ(config.exit_code, 2) << config.output;
  EXPECT_TRUE(contains(config.output, "--driver-config: only with --device plugin:PATH.so"))
      << config.output;
#ifdef HAPSIM_EXAMPLE_DRIVER
  const RunResult refused = test::run_hapsim_env(
      "env -u DISPLAY", "view " + kBlock + " --device plugin:" + HAPSIM_EXAMPLE_DRIVER +
                            " --driver-config colour=red --duration 1");
  EXPECT_EQ(refused.exit_code, 2) << refused.output;
  EXPECT_TRUE(contains(refused.output, "unknown key 'colour'")) << refused.output;
#endif
}

#ifdef HAPSIM_EXAMPLE_DRIVER
// The viewer on the CSG block with the example driver, as `run` above: its window and JSON name
// the plugin, its presses reach the block (a force, none above the plugin's 5 N), and the last
// frame shows the tool (the green sphere) over the block.
TEST(RunPluginDevice, TheViewerRunsWithThePluginsDevice) {
  if (std::system("command -v xvfb-run > /dev/null 2>&1") != 0) {
    GTEST_SKIP() << "xvfb-run missing (scripts/setup.sh installs it)";
  }
  const auto json_path = temp_path("view-plugin.json");
  const auto png = temp_path("view-plugin.png");
  const auto log = temp_path("view-plugin.log");
  const std::string cmd =
      std::string("xvfb-run -a -s '-screen 0 1280x720x24' ") + HAPSIM_BIN_PATH + " view " + kBlock +
      kPlugin + " --duration 2.5 --no-panels --size 640x480 --json " + json_path.string() +
      " --screenshot " + png.string() + " > " + log.string() + " 2>&1";
  const int status = std::system(cmd.c_str());
  std::ifstream log_in(log);
  const std::string output((std::istreambuf_iterator<char>(log_in)), {});
  ASSERT_TRUE(WIFEXITED(status) && WEXITSTATUS(status) == 0) << output;
  EXPECT_TRUE(contains(output, "plugin 'example-circle-press' (" +
                                   std::string(HAPSIM_EXAMPLE_DRIVER) + ", rated 5.0 N"))
      << output;

  std::ifstream in(json_path);
  const nlohmann::json j = nlohmann::json::parse(in);
  EXPECT_TRUE(contains(j.at("device").get<std::string>(), "plugin 'example-circle-press'"));
  EXPECT_TRUE(j.at("ok").get<bool>()) << j.dump(2);
  ASSERT_EQ(j.at("peak_force_n").size(), 1u) << j.dump(2);
  EXPECT_GT(j["peak_force_n"][0].get<double>(), 0.5) << j.dump(2);
  EXPECT_LE(j["peak_force_n"][0].get<double>(), 5.0 + 1e-9) << j.dump(2);

  // The tool is drawn over the block's top face, where the driver's circle is: the tool's
  // colours (green free, red in contact, the yellow force arrow: red or green well above blue,
  // which neither the grey floor and background nor the blue block are) in the picture's upper
  // middle. The viewer's own mouse probe would start low on the left.
  const RgbaImage image = read_png(png.string());
  ASSERT_EQ(image.width, 640);
  int tool = 0;
  double sum_x = 0.0;
  double sum_y = 0.0;
  for (int y = 0; y < image.height; ++y) {
    for (int x = 0; x < image.width; ++x) {
      const std::uint8_t* p = &image.rgba[(static_cast<std::size_t>(y) * image.width + x) * 4];
      const int warm = std::max(p[0], p[1]);
      if (warm > 120 && 2 * p[2] < warm) {
        ++tool;
        sum_x += x;
        sum_y += y;
      }
    }
  }
  ASSERT_GT(tool, 100) << "no tool drawn in " << png;
  EXPECT_NEAR(sum_x / tool, 0.5 * image.width, 0.1 * image.width) << png;
  EXPECT_LT(sum_y / tool, 0.45 * image.height) << png;
}
#endif

}  // namespace
}  // namespace hapsim
