// `hapsim run SCENE --device plugin:PATH.so`: a driver plugin's device drives the world on the
// real-time loop (the example driver, examples/device_plugin, pressing the CSG block's top face
// from its own frame), the summary and the JSON name it, the world renders no stiffer than the
// plugin's rating, and every wrong use is one named line with exit status 2. `hapsim view` says
// plainly that it does not drive a plugin yet.
#include "hapsim_process.h"

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <fstream>
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

TEST(RunPluginDevice, TheViewerSaysItDoesNotDriveAPluginYet) {
  const RunResult r = run_hapsim("view " + kBlock + " --device plugin:/some/driver.so");
  EXPECT_EQ(r.exit_code, 2) << r.output;
  EXPECT_TRUE(contains(r.output, "the viewer does not drive a plugin's device yet")) << r.output;
  EXPECT_TRUE(contains(r.output, "hapsim doctor --device plugin:/some/driver.so")) << r.output;
}

}  // namespace
}  // namespace hapsim
