// A FEM body served (issue 29, item 3): `hapsim serve scenes/fem_block.json --wait-for-device` +
// `hapsim device` on loopback. The FEM runs on serve's FEM thread, hands serve's cycle its local
// contact model, and serve passes the FEM's series stiffness on to the device host, which renders
// it from its own position: what the device felt peaks where the one-process run's force does.
// Progress, not speed, is asserted (a loaded machine adopts some FEM updates late).
#include "apps/hapsim_process.h"
#include "net/net_test_support.h"

#include <nlohmann/json.hpp>

#include <fstream>
#include <string>

#include <gtest/gtest.h>

namespace hapsim::net {
namespace {

using namespace std::chrono_literals;
using hapsim::test::BackgroundHapsim;

const std::string kScene = std::string(HAPSIM_SOURCE_DIR) + "/scenes/fem_block.json";

nlohmann::json read_json(const std::filesystem::path& path) {
  std::ifstream in(path);
  return nlohmann::json::parse(in);
}

TEST(FemServe, AServedFemBlockIsFeltByTheDeviceHostAsInOneProcess) {
  ASSERT_TRUE(test::on_loopback_config());
  const auto one_json = hapsim::test::temp_path("fem_one.json");
  const auto served_json = hapsim::test::temp_path("fem_served.json");
  const auto device_json = hapsim::test::temp_path("fem_device.json");
  const hapsim::test::RunResult one =
      hapsim::test::run_hapsim("run " + kScene + " --quiet --json " + one_json.string());
  ASSERT_EQ(one.exit_code, 0) << one.output;
  const std::string net = " --session fem-serve --domain 77";
  BackgroundHapsim serve(
      "serve " + kScene + " --wait-for-device --duration 7.2 --json " + served_json.string() + net,
      hapsim::test::temp_path("fem_serve.log"));
  ASSERT_TRUE(serve.wait_for("waiting", 30s)) << serve.output();
  BackgroundHapsim device("device --duration 7.7" + net + " --json " + device_json.string(),
                          hapsim::test::temp_path("fem_device.log"));
  ASSERT_EQ(serve.wait(), 0) << serve.output();
  ASSERT_EQ(device.wait(), 0) << device.output();

  const nlohmann::json a = read_json(one_json);
  const nlohmann::json b = read_json(served_json);
  const nlohmann::json d = read_json(device_json);
  ASSERT_TRUE(b.contains("fem")) << b.dump(2);
  // On serve's own FEM thread, 720 periods of 10 ms: ~700 idle, 139 with both cores busy
  // (stress-ng beside another test). Progress: at least one update in ten periods.
  EXPECT_GT(b["fem"]["updates"].get<int>(), 72);
  EXPECT_EQ(b["fem"]["failures"].get<int>(), 0);
  const double one_peak_n = a["tools"][0]["peak_force_n"].get<double>();
  EXPECT_GT(one_peak_n, 1.0);  // the palpation pressed the block
  // The device's own rendering of the FEM's local models: 1.826 against 1.815 N measured on an
  // idle machine, but 2.65 N beside a cold build and a benchmark (FEM updates adopted late, the
  // device pressing on a model tens of ms old): progress and an upper bound, not the idle figure.
  EXPECT_GT(d["peak_force_n"].get<double>(), 0.85 * one_peak_n);
  EXPECT_LT(d["peak_force_n"].get<double>(), 1.6 * one_peak_n);
  EXPECT_EQ(d["models"]["malformed"].get<int>(), 0);
  EXPECT_GT(d["models_rendered"].get<int>(), 3'000);
  EXPECT_EQ(b["pop_throughs"].get<int>(), 0);
}

}  // namespace
}  // namespace hapsim::net
