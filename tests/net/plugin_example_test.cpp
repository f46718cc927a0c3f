// The plugin example documented in docs/devices.md, run as written there (the serve and device
// command lines are read from the page): the example driver's tool starts outside the knee and
// the served run is clean (no pop-through, `ok: true`). Its default centre is inside the knee:
// run from there, a tool that starts in a body is the docs' first picture of hapsim.
#include "apps/hapsim_process.h"
#include "net/net_test_support.h"

#include <nlohmann/json.hpp>

#include <csignal>
#include <fstream>
#include <regex>
#include <sstream>

#include <gtest/gtest.h>

namespace hapsim::net {
namespace {

using namespace std::chrono_literals;
using hapsim::test::BackgroundHapsim;

#if defined(HAPSIM_EXAMPLE_DRIVER)
TEST(PluginExample, TheDocumentedCommandStartsOutsideAndRunsClean) {
  ASSERT_TRUE(test::on_loopback_config());
  std::ifstream page(std::string(HAPSIM_SOURCE_DIR) + "/docs/devices.md");
  std::stringstream text;
  text << page.rdbuf();
  const std::string docs = text.str();
  static const std::regex kExample(
      R"(`hapsim serve (\S+)((?: --\S+)*) & hapsim device --device plugin:\S+hapsim_example_device\.so((?: \S+)*)`)");
  std::smatch m;
  ASSERT_TRUE(std::regex_search(docs, m, kExample)) << "docs/devices.md lost its plugin example";
  const std::string scene = std::string(HAPSIM_SOURCE_DIR) + "/" + m[1].str();
  const std::string serve_options = m[2].str();
  const std::string device_options = m[3].str();

  const auto serve_json = hapsim::test::temp_path("plugin-example-serve.json");
  const std::string net = " --session plugin-example --domain 81";
  BackgroundHapsim serve(
      "serve " + scene + serve_options + " --duration 60 --json " + serve_json.string() + net,
      hapsim::test::temp_path("plugin-example-serve.log"));
  ASSERT_TRUE(serve.wait_for("dds ", 20s)) << serve.output();
  // 4 s: the circle round once, four presses.
  BackgroundHapsim device(std::string("device --device plugin:") + HAPSIM_EXAMPLE_DRIVER +
                              device_options + " --duration 4" + net,
                          hapsim::test::temp_path("plugin-example-device.log"));
  EXPECT_EQ(device.wait(), 0) << device.output();
  serve.signal(SIGINT);
  EXPECT_EQ(serve.wait(), 130) << serve.output();
  ASSERT_NE(serve.output().find("device host  joined"), std::string::npos) << serve.output();
  std::ifstream in(serve_json);
  const nlohmann::json j = nlohmann::json::parse(in);
  // A tool that started inside would be a pop-through (or a start-inside) from the first state.
  EXPECT_EQ(j["pop_throughs"].get<int>(), 0) << serve.output();
  EXPECT_GT(j["steps"].get<int>(), 1000) << serve.output();
  if (serve.output().find("device host  silent") != std::string::npos) {
    GTEST_SKIP() << "the device host fell silent on this machine and the scene's script drove the "
                    "world meanwhile: its forces are not the example's\n"
                 << serve.output();
  }
  EXPECT_TRUE(j["ok"].get<bool>()) << serve.output();
}
#endif

}  // namespace
}  // namespace hapsim::net
