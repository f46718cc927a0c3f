// The distributed palpation (issue 12) as separate processes on loopback, against the same run in
// one process:
//  * `hapsim serve --wait-for-device` + `hapsim device` (the simulated device playing the knee's
//    palpation) reproduce `hapsim run`'s contacts per segment and peak forces within 5 %, and the
//    force the device rendered from its local models peaks within 5 % of the one-process force;
//  * killing serve mid-contact takes the device's force to zero within 150 of its cycles (150 ms)
//    of its last model, the device keeps running and renders again when a new serve comes; when
//    the device stops, serve keeps running and says so;
//  * a second serve on the session does not capture the device host.
#include "hapsim/net/participant.h"
#include "hapsim/net/topic_reader.h"

#include "apps/hapsim_process.h"
#include "net/net_test_support.h"

#include <nlohmann/json.hpp>

#include <algorithm>
#include <array>
#include <csignal>
#include <cstdint>
#include <cstdlib>
#include <fstream>
#include <map>
#include <string>
#include <thread>

#include <gtest/gtest.h>

namespace hapsim::net {
namespace {

using namespace std::chrono_literals;
using hapsim::test::BackgroundHapsim;
using Clock = std::chrono::steady_clock;

const std::string kScene = std::string(HAPSIM_SOURCE_DIR) + "/scenes/knee_procedural.json";

nlohmann::json read_json(const std::filesystem::path& path) {
  std::ifstream in(path);
  return nlohmann::json::parse(in);
}

// Per segment name: (tool-steps in contact, peak force).
std::map<std::string, std::pair<double, double>> segments(const nlohmann::json& run) {
  std::map<std::string, std::pair<double, double>> out;
  for (const auto& s : run["segments"]) {
    out[s["name"].get<std::string>()] = {s["contacts"].get<double>(),
                                         s["peak_force_n"].get<double>()};
  }
  return out;
}

// The tool's peak force in a `hapsim run --json` file.
double a_peak_n(const std::filesystem::path& run_json) {
  return read_json(run_json)["tools"][0]["peak_force_n"].get<double>();
}

TEST(ThreeProcesses, ServeAndDeviceReproduceTheOneProcessPalpation) {
  ASSERT_TRUE(test::on_loopback_config());
  const auto one_json = hapsim::test::temp_path("one.json");
  const auto served_json = hapsim::test::temp_path("served.json");
  const auto device_json = hapsim::test::temp_path("device.json");
  const hapsim::test::RunResult one =
      hapsim::test::run_hapsim("run " + kScene + " --quiet --json " + one_json.string());
  ASSERT_EQ(one.exit_code, 0) << one.output;

  const std::string net = " --session three-proc --domain 75";
  BackgroundHapsim serve(
      "serve " + kScene + " --wait-for-device --duration 10.5 --json " + served_json.string() + net,
      hapsim::test::temp_path("serve.log"));
  ASSERT_TRUE(serve.wait_for("waiting", 20s)) << serve.output();
  // A headless viewer (hapsim watch) from the start, drawing the view at the largest force.
  const auto watch_json = hapsim::test::temp_path("watch.json");
  const auto watch_png = hapsim::test::temp_path("watch.png");
  BackgroundHapsim watch("watch --duration 11.5 --json " + watch_json.string() + " --snapshot " +
                             watch_png.string() + net,
                         hapsim::test::temp_path("watch.log"));
  BackgroundHapsim device("device --duration 11" + net + " --json " + device_json.string(),
                          hapsim::test::temp_path("device.log"));
  // The third process: a viewer that joins after the palpation started, under a virtual display.
  const auto view_json = hapsim::test::temp_path("view.json");
  const auto view_png = hapsim::test::temp_path("view.png");
  const bool have_xvfb = std::system("command -v xvfb-run > /dev/null 2>&1") == 0;
  hapsim::test::RunResult viewed;
  std::thread viewer;
  if (have_xvfb) {
    // It joins once the device says serve answers it (the palpation's start), not after a fixed
    // 1.5 s: a loaded machine's device joined late and a viewer timed from its launch watched
    // 5 s that held no press (0 N, 0.28 mm).
    EXPECT_TRUE(device.wait_for("host answering", 60s)) << device.output();
    viewer = std::thread([&] {
      const std::string cmd = "xvfb-run -a -s '-screen 0 1280x720x24' " +
                              std::string(HAPSIM_BIN_PATH) + " view --connect" + net +
                              " --duration 5 --json " + view_json.string() + " --screenshot " +
                              view_png.string() + " 2>&1";
      std::FILE* pipe = popen(cmd.c_str(), "r");
      std::array<char, 4096> buffer{};
      while (pipe != nullptr &&
             std::fgets(buffer.data(), static_cast<int>(buffer.size()), pipe) != nullptr) {
        viewed.output += buffer.data();
      }
      const int status = pipe != nullptr ? pclose(pipe) : -1;
      viewed.exit_code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
    });
  } else {
    std::printf("SKIPPED the viewer: xvfb-run is not installed (scripts/setup.sh installs it)\n");
  }
  EXPECT_EQ(serve.wait(), 0) << serve.output();
  EXPECT_EQ(device.wait(), 0) << device.output();
  if (viewer.joinable()) {
    viewer.join();
  }
  EXPECT_EQ(watch.wait(), 0) << watch.output();
  // Everything below assumes serve kept its 1 kHz (rates, and forces compared with one process).
  if (const std::string why = test::serve_too_slow_for_real_time(serve.output()); !why.empty()) {
    GTEST_SKIP() << why;
  }
  {
    const nlohmann::json w = read_json(watch_json);
    // Progress, not rate: the views span the palpation (10.5 s of 1 kHz cycles) and came at
    // least ten a second, a third of serve's 30 (a loaded machine's watch lags, not loses them).
    const auto cycles = w["cycles"].get<std::array<std::uint64_t, 2>>();
    EXPECT_GT(cycles[1] - cycles[0], 9'000u);
    EXPECT_GT(w["views"].get<int>(), 100);
    EXPECT_EQ(w["refused"].get<int>(), 0);
    // A view samples serve's force every ~33 ms (longer under load): its largest is not above
    // serve's peak (5 % for the world's force before the device's safety stage) and, the patella
    // held pressed over several views, within 15 % below it.
    const double served_peak_n = a_peak_n(served_json);
    EXPECT_LE(w["peak_force_n"].get<double>(), 1.05 * served_peak_n);
    EXPECT_GE(w["peak_force_n"].get<double>(), 0.85 * served_peak_n);
    EXPECT_GT(w["max_deflection_m"].get<double>(), 0.005);
    EXPECT_TRUE(std::filesystem::exists(watch_png));
  }
  std::printf("%s\n%s\n%s\n", serve.output().c_str(), device.output().c_str(),
              viewed.output.c_str());
  if (have_xvfb) {
    // It drew the served palpation as it went: forces and the skin's dent, from view states only.
    ASSERT_EQ(viewed.exit_code, 0) << viewed.output;
    const nlohmann::json v = read_json(view_json);
    // Joining after the start for 5 s, it may miss the hardest press when a loaded machine starts
    // it late (4.2-4.9 N seen beside an ASan run): it drew served forces, not that it saw the peak.
    EXPECT_GT(v["peak_force_n"][0].get<double>(), 1.0);
    EXPECT_GT(v["max_deflection_m"].get<double>(), 0.005);
    EXPECT_TRUE(std::filesystem::exists(view_png));
  }

  const nlohmann::json a = read_json(one_json);
  const nlohmann::json b = read_json(served_json);
  const nlohmann::json d = read_json(device_json);
  const auto one_segments = segments(a);
  const auto served_segments = segments(b);
  // Contacts are counted in serve's steps, but the device plays the palpation by its own clock:
  // a serve that simulated at pace p < 1 (its steps late against the device's wall-clock time)
  // sees the same touch in about p times as many steps (a loaded 2-core machine: 679 contacts
  // against 733, serve at ~0.93x). So the served count lies between p times the one-process count
  // and the count itself, each within 5 %: never more, and never less than serve's pace explains.
  const double pace = test::serve_pace(serve.output());
  ASSERT_GT(pace, 0.0) << serve.output();
  ASSERT_EQ(one_segments.size(), served_segments.size());
  const double one_tool_peak_n = a["tools"][0]["peak_force_n"].get<double>();
  for (const auto& [name, counts] : one_segments) {
    const auto& [contacts, peak_n] = counts;
    ASSERT_TRUE(served_segments.count(name)) << name;
    const auto& [served_contacts, served_peak_n] = served_segments.at(name);
    EXPECT_GE(served_contacts, 0.95 * std::min(pace, 1.0) * contacts - 1.0) << name;
    EXPECT_LE(served_contacts, 1.05 * contacts + 1.0) << name;
    // Each segment pressed as hard as in one process. Not more than 5 % harder, except where a
    // press on a boundary went to the neighbour: under load serve steps on states that arrive in
    // bursts, its tool jumps a few device periods at once, and the proxy can come to rest on the
    // next segment for a step (the patellar tendon took the patella's 8 N in 1 of 20 runs under
    // stress-ng). The tool's own peak below stays within 5 %.
    EXPECT_GE(served_peak_n, 0.95 * peak_n - 1e-9) << name;
    EXPECT_LE(served_peak_n, 1.05 * one_tool_peak_n) << name;
  }
  const double one_peak_n = one_tool_peak_n;
  EXPECT_GT(one_peak_n, 5.0);  // the palpation pressed
  EXPECT_NEAR(b["tools"][0]["peak_force_n"].get<double>(), one_peak_n, 0.05 * one_peak_n);
  // What the device felt, rendered from its own local models at its own position.
  EXPECT_NEAR(d["peak_force_n"].get<double>(), one_peak_n, 0.05 * one_peak_n);
  EXPECT_EQ(b["pop_throughs"].get<int>(), 0);
  EXPECT_EQ(b["serve"]["device_states"]["malformed"].get<int>(), 0);
  EXPECT_GT(b["serve"]["device_host_cycles"].get<int>(), 10'000);  // the device drove it all
  EXPECT_EQ(d["models"]["malformed"].get<int>(), 0);
  // Rendered throughout (progress, not rate: 8 168 of 10 500 beside an ASan run and a fuzzer); what
  // it felt is checked above.
  EXPECT_GT(d["models_rendered"].get<int>(), 5'000);
}

TEST(ThreeProcesses, KillingServeFadesTheForceAndTheDeviceRendersAgainWhenItReturns) {
  ASSERT_TRUE(test::on_loopback_config());
  const auto device_json = hapsim::test::temp_path("device-kill.json");
  const std::string net = " --session kill-test --domain 76";
  auto serve = std::make_unique<BackgroundHapsim>("serve " + kScene + net,
                                                  hapsim::test::temp_path("serve-1.log"));
  ASSERT_TRUE(serve->wait_for("dds ", 20s)) << serve->output();
  // The device runs until stopped (120 s bounds a hang): a slow build's second serve may take
  // longer than the palpation's 9 s to load and join.
  // It says when its force rises above 2 N: serve is killed then, mid-contact, however late a
  // loaded machine starts the palpation (a fixed 3.3 s sleep once killed it at 0.19 N).
  BackgroundHapsim device(
      "device --duration 120 --say-force-above 2" + net + " --json " + device_json.string(),
      hapsim::test::temp_path("device-kill.log"));
  ASSERT_TRUE(device.wait_for("host answering", 60s)) << device.output();
  ASSERT_TRUE(device.wait_for("force        above 2.00 N", 60s)) << device.output();
  serve->signal(SIGKILL);
  serve->wait();
  ASSERT_TRUE(device.wait_for("host silent", 30s)) << device.output();
  std::this_thread::sleep_for(500ms);
  serve = std::make_unique<BackgroundHapsim>("serve " + kScene + net,
                                             hapsim::test::temp_path("serve-2.log"));
  EXPECT_TRUE(device.wait_for("host back", 120s)) << device.output();
  std::this_thread::sleep_for(1s);  // rendering the new serve's models
  device.signal(SIGTERM);
  EXPECT_EQ(device.wait(), 143) << device.output();  // 128 + SIGTERM, its JSON written
  // The device is gone: serve goes on with the scene's script and says so.
  EXPECT_TRUE(serve->wait_for("device host  silent", 30s)) << serve->output();
  serve->signal(SIGTERM);
  EXPECT_EQ(serve->wait(), 143) << serve->output();
  std::printf("%s\n%s\n", device.output().c_str(), serve->output().c_str());

  const nlohmann::json d = read_json(device_json);
  ASSERT_GE(d["silences"].size(), 1u);
  const nlohmann::json& kill = d["silences"][0];
  EXPECT_GT(kill["force_before_n"].get<double>(), 1.0) << "serve was not killed mid-contact";
  // The fade (100 ms stale, then 50 ms down) counted in the device loop's own cycles, which a
  // loaded machine can only make fewer (a late cycle is not caught up), never more: 150 at 1 kHz,
  // and the cycle that took the last model.
  EXPECT_LE(kill["force_zero_after_cycles"].get<int>(), 151) << kill.dump();
  EXPECT_GT(kill["force_zero_after_cycles"].get<int>(), 0) << kill.dump();
  EXPECT_EQ(d["simulation_joins"].get<int>(), 2);
  EXPECT_NE(serve->output().find("device host  joined"), std::string::npos);
}

// A second `hapsim serve` on the session (another scene) while the first answers the device:
// the device host reports it and keeps following the first (its models refused as from another
// host), instead of being captured by it (it once took the device to 12 N and cut the first serve
// off for good).
TEST(ThreeProcesses, ASecondServeOnTheSessionDoesNotCaptureTheDeviceHost) {
  ASSERT_TRUE(test::on_loopback_config());
  const auto device_json = hapsim::test::temp_path("device-second-serve.json");
  const std::string net = " --session second-serve --domain 79";
  BackgroundHapsim first("serve " + kScene + net + " --duration 120",
                         hapsim::test::temp_path("serve-first.log"));
  ASSERT_TRUE(first.wait_for("dds ", 60s)) << first.output();
  BackgroundHapsim device("device --duration 120" + net + " --json " + device_json.string(),
                          hapsim::test::temp_path("device-second-serve.log"));
  ASSERT_TRUE(device.wait_for("host answering", 60s)) << device.output();
  // The session's models, seen from here too: the first serve's scene hash, then the second's.
  Participant participant(79, "second-serve");
  TopicReader<hapsim_msg_LocalModel> models(participant);
  std::uint64_t first_hash = 0;
  for (const auto give_up = Clock::now() + 60s; first_hash == 0 && Clock::now() < give_up;) {
    models.take([&](const hapsim_msg_LocalModel& m, const dds_sample_info_t&) {
      first_hash = m.scene_hash;
    });
    std::this_thread::sleep_for(2ms);
  }
  ASSERT_NE(first_hash, 0u) << "no model from the first serve";
  BackgroundHapsim second("serve " + std::string(HAPSIM_SOURCE_DIR) + "/scenes/csg_block.json" +
                              net + " --duration 120",
                          hapsim::test::temp_path("serve-second.log"));
  ASSERT_TRUE(device.wait_for("another host on the session", 60s)) << device.output();
  // Both serves publish for a while (the second, another scene, runs its own script: it refuses
  // the device's states): its models keep arriving at the device and keep being refused. Until
  // 200 of them arrived here (progress, not a time: a cold machine's second serve took a second
  // to publish its first ten).
  int second_models = 0;
  for (const auto give_up = Clock::now() + 60s; second_models < 200 && Clock::now() < give_up;) {
    models.take([&](const hapsim_msg_LocalModel& m, const dds_sample_info_t&) {
      second_models += m.scene_hash != first_hash ? 1 : 0;
    });
    std::this_thread::sleep_for(2ms);
  }
  ASSERT_GE(second_models, 200) << second.output();
  device.signal(SIGTERM);
  EXPECT_EQ(device.wait(), 143) << device.output();
  second.signal(SIGTERM);
  first.signal(SIGTERM);
  EXPECT_EQ(second.wait(), 143) << second.output();
  EXPECT_EQ(first.wait(), 143) << first.output();

  const nlohmann::json d = read_json(device_json);
  EXPECT_EQ(d["other_simulation_hosts"].get<int>(), 1) << d.dump(2);
  EXPECT_GT(d["models"]["other host"].get<int>(), 10) << d.dump(2);
  // Never went over to the second (a loaded machine may starve the first's models for a few
  // hundred ms, a silence and a "host back": the device still waits for it).
  EXPECT_EQ(device.output().find("host restarted"), std::string::npos) << device.output();
}

}  // namespace
}  // namespace hapsim::net
