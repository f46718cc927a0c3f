// SIGINT to the long-running network commands (issue 31): `hapsim watch`, `hapsim device` and
// `hapsim serve` stop their loop, write their summary and their JSON (which says what stopped
// them), and exit 130 (128 + SIGINT), as a shell expects. A snapshot that cannot be written (a
// full disk) is one line and exit 2, and the JSON is still written with the failure in it. Waits
// are on what the processes report (progress), never fixed sleeps, so a loaded machine is only
// slower.
#include "hapsim/net/loaned_reader.h"

#include "apps/hapsim_process.h"
#include "net/net_test_support.h"
#include "support/small_tmpfs.h"

#include <nlohmann/json.hpp>

#include <chrono>
#include <filesystem>
#include <fstream>
#include <string>
#include <thread>

#include <gtest/gtest.h>

namespace hapsim::net {
namespace {

using namespace std::chrono_literals;
using hapsim::test::BackgroundHapsim;
using Clock = std::chrono::steady_clock;

const std::string kScene = std::string(HAPSIM_SOURCE_DIR) + "/scenes/csg_block.json";

nlohmann::json read_json(const std::filesystem::path& path) {
  std::ifstream in(path);
  return nlohmann::json::parse(in);  // throws (fails the test) on an empty or partial file
}

// Until `count` view states of the session arrived here (a bound on a hang: 60 s).
bool views_arrive(LoanedReader<hapsim_msg_ViewState>& views, int count) {
  int seen = 0;
  for (const auto give_up = Clock::now() + 60s; seen < count && Clock::now() < give_up;) {
    views.take([&](const hapsim_msg_ViewState&) { ++seen; });
    std::this_thread::sleep_for(2ms);
  }
  return seen >= count;
}

TEST(StopSignalProcess, SigintStopsWatchDeviceAndServeWithTheirSummaryAndJson) {
  ASSERT_TRUE(test::on_loopback_config());
  const std::string net = " --session stop-signal-test --domain 81";
  const auto serve_json = hapsim::test::temp_path("stop-serve.json");
  const auto device_json = hapsim::test::temp_path("stop-device.json");
  const auto watch_json = hapsim::test::temp_path("stop-watch.json");
  BackgroundHapsim serve("serve " + kScene + " --duration 600 --json " + serve_json.string() + net,
                         hapsim::test::temp_path("stop-serve.log"));
  ASSERT_TRUE(serve.wait_for("dds ", 60s)) << serve.output();
  BackgroundHapsim watch("watch --duration 600 --wait 60 --json " + watch_json.string() + net,
                         hapsim::test::temp_path("stop-watch.log"));
  ASSERT_TRUE(watch.wait_for("watching ", 60s)) << watch.output();
  BackgroundHapsim device("device --duration 600 --json " + device_json.string() + net,
                          hapsim::test::temp_path("stop-device.log"));
  ASSERT_TRUE(device.wait_for("host answering", 60s)) << device.output();
  // Views flow after watch joined: watch has seen some too.
  Participant participant(81, "stop-signal-test");
  LoanedReader<hapsim_msg_ViewState> views(participant);
  ASSERT_TRUE(views_arrive(views, 20)) << serve.output();

  watch.signal(SIGINT);
  EXPECT_EQ(watch.wait(), 130) << watch.output();
  EXPECT_NE(watch.output().find("views        "), std::string::npos) << watch.output();
  const nlohmann::json w = read_json(watch_json);
  EXPECT_EQ(w["stopped_by"], "SIGINT");
  EXPECT_GT(w["views"].get<int>(), 0);
  EXPECT_EQ(w["ok"], true);

  device.signal(SIGINT);
  EXPECT_EQ(device.wait(), 130) << device.output();
  EXPECT_NE(device.output().find("ran          "), std::string::npos) << device.output();
  const nlohmann::json d = read_json(device_json);
  EXPECT_EQ(d["stopped_by"], "SIGINT");
  EXPECT_GT(d["models_rendered"].get<int>(), 0);

  serve.signal(SIGINT);
  EXPECT_EQ(serve.wait(), 130) << serve.output();
  EXPECT_NE(serve.output().find("published    "), std::string::npos) << serve.output();
  const nlohmann::json s = read_json(serve_json);
  EXPECT_EQ(s["stopped_by"], "SIGINT");
  EXPECT_GT(s["serve"]["device_host_cycles"].get<int>(), 0);
}

// A paused serve steps no cycle, so it makes no cycle record; SIGINT was looked for only when a
// record came, and a paused serve kept running after Ctrl-C. It stops, with its JSON, exit 130.
TEST(StopSignalProcess, SigintStopsAPausedServe) {
  ASSERT_TRUE(test::on_loopback_config());
  const std::string net = " --session stop-paused --domain 82";
  const auto serve_json = hapsim::test::temp_path("stop-paused-serve.json");
  BackgroundHapsim serve("serve " + kScene + " --duration 600 --json " + serve_json.string() + net,
                         hapsim::test::temp_path("stop-paused-serve.log"));
  ASSERT_TRUE(serve.wait_for("dds ", 60s)) << serve.output();
  // It returns once a view state shows the world paused.
  const hapsim::test::RunResult pause =
      hapsim::test::run_hapsim("control pause" + net + " --timeout 60");
  ASSERT_EQ(pause.exit_code, 0) << pause.output << serve.output();
  serve.signal(SIGINT);
  ASSERT_TRUE(serve.wait_for("published    ", 60s)) << "a paused serve ignored SIGINT\n"
                                                    << serve.output();
  EXPECT_EQ(serve.wait(), 130) << serve.output();
  const nlohmann::json j = read_json(serve_json);
  EXPECT_EQ(j["stopped_by"], "SIGINT");
}

TEST(StopSignalProcess, SigtermBeforeAHostJoinedStillWritesTheJson) {
  ASSERT_TRUE(test::on_loopback_config());
  const auto device_json = hapsim::test::temp_path("stop-early-device.json");
  BackgroundHapsim device(
      "device --json " + device_json.string() + " --session stop-signal-nobody --domain 81",
      hapsim::test::temp_path("stop-early-device.log"));
  ASSERT_TRUE(device.wait_for("waiting      for a simulation host", 60s)) << device.output();
  device.signal(SIGTERM);
  EXPECT_EQ(device.wait(), 143) << device.output();
  const nlohmann::json d = read_json(device_json);
  EXPECT_EQ(d["ok"], false);
  EXPECT_NE(d["error"].get<std::string>().find("SIGTERM"), std::string::npos) << d.dump();
}

TEST(StopSignalProcess, WatchSnapshotOnAFullDiskIsOneLineAndTheJsonSaysIt) {
  ASSERT_TRUE(test::on_loopback_config());
  const hapsim::test::SmallTmpfs disk("watch_snapshot", 16);
  if (!disk.mounted()) {
    GTEST_SKIP() << disk.why_not();
  }
  const std::string net = " --session stop-signal-snap --domain 81";
  BackgroundHapsim serve("serve " + kScene + " --duration 600" + net,
                         hapsim::test::temp_path("snap-serve.log"));
  ASSERT_TRUE(serve.wait_for("dds ", 60s)) << serve.output();
  const auto png = disk.dir() / "peak.png";
  const auto watch_json = hapsim::test::temp_path("snap-watch.json");
  BackgroundHapsim watch("watch --duration 600 --wait 60 --snapshot " + png.string() + " --json " +
                             watch_json.string() + net,
                         hapsim::test::temp_path("snap-watch.log"));
  ASSERT_TRUE(watch.wait_for("watching ", 60s)) << watch.output();
  Participant participant(81, "stop-signal-snap");
  LoanedReader<hapsim_msg_ViewState> views(participant);
  ASSERT_TRUE(views_arrive(views, 20)) << serve.output();
  watch.signal(SIGINT);
  const int status = watch.wait();
  serve.signal(SIGINT);
  (void)serve.wait();
  if (watch.output().find("no display") != std::string::npos ||
      watch.output().find("EGL") != std::string::npos) {
    GTEST_SKIP() << "no offscreen rendering here: " << watch.output();
  }
  EXPECT_EQ(status, 2) << watch.output();
  EXPECT_NE(watch.output().find("hapsim: --snapshot " + png.string() +
                                ": write failed (No space left on device)"),
            std::string::npos)
      << watch.output();
  EXPECT_NE(watch.output().find("views        "), std::string::npos) << watch.output();
  EXPECT_FALSE(std::filesystem::exists(png));
  const nlohmann::json w = read_json(watch_json);
  EXPECT_EQ(w["ok"], false);
  EXPECT_NE(w["snapshot_error"].get<std::string>().find("No space left"), std::string::npos);
}

}  // namespace
}  // namespace hapsim::net
