// `hapsim control` against `hapsim serve` on loopback: pause holds the served world still (its
// time stops, and the models it serves are free space, so a device's force goes to zero), resume
// lets it run again, reset takes it back to the scene's start, a material change is applied and
// said; a command for another start of the host is dropped and counted; bad requests are one line
// and exit 2.
#include "hapsim/net/loaned_reader.h"
#include "hapsim/net/scene_info.h"
#include "hapsim/net/served_scene.h"
#include "hapsim/net/session_command.h"
#include "hapsim/net/topic_reader.h"
#include "hapsim/net/topic_writer.h"

#include "apps/hapsim_process.h"
#include "net/net_test_support.h"

#include <nlohmann/json.hpp>

#include <chrono>
#include <fstream>
#include <regex>
#include <thread>

#include <gtest/gtest.h>

namespace hapsim::net {
namespace {

using Clock = std::chrono::steady_clock;

constexpr dds_domainid_t kDomain = 80;
const std::string kNet = " --session control-test --domain 80";
// How long a control command waits for serve's answer: a bound on a hang, not a time asserted (the
// default 5 s was too short for a material change under a Debug ASan build).
const std::string kControl = kNet + " --timeout 60";
const std::string kScene = std::string(HAPSIM_SOURCE_DIR) + "/scenes/csg_block.json";

// What a viewer would see over `window`: the served world's times, and the models served.
struct Observed {
  double first_time_s = -1.0;
  double last_time_s = -1.0;
  std::uint64_t views = 0;
  std::uint64_t views_paused = 0;
  std::uint64_t models = 0;
  std::uint64_t valid_models = 0;
};

// Watches until at least `min_views` views and `min_models` models arrived: progress, not a
// time, so a loaded machine only makes it slower (the bound is a hang's, not a rate asserted).
Observed observe(LoanedReader<hapsim_msg_ViewState>& views,
                 TopicReader<hapsim_msg_LocalModel>& models, std::uint64_t min_views,
                 std::uint64_t min_models = 0) {
  Observed o;
  for (const auto give_up = Clock::now() + std::chrono::seconds(30);
       (o.views < min_views || o.models < min_models) && Clock::now() < give_up;) {
    views.take([&](const hapsim_msg_ViewState& m) {
      o.first_time_s = o.views == 0 ? m.sim_time_s : o.first_time_s;
      o.last_time_s = m.sim_time_s;
      ++o.views;
      o.views_paused += m.paused ? 1 : 0;
    });
    models.take([&](const hapsim_msg_LocalModel& m, const dds_sample_info_t&) {
      ++o.models;
      o.valid_models += m.valid ? 1 : 0;
    });
    std::this_thread::sleep_for(std::chrono::milliseconds(1));
  }
  return o;
}

// Drops what is on the way (views and models sent before the last command took effect).
void drain(LoanedReader<hapsim_msg_ViewState>& views, TopicReader<hapsim_msg_LocalModel>& models) {
  views.take([](const hapsim_msg_ViewState&) {});
  while (models.take([](const hapsim_msg_LocalModel&, const dds_sample_info_t&) {}) > 0) {
  }
}

TEST(ControlProcess, PausesResumesResetsAndRetunesAServedWorld) {
  ASSERT_TRUE(test::on_loopback_config());
  const auto json_path = hapsim::test::temp_path("control-serve.json");
  hapsim::test::BackgroundHapsim serve(
      "serve " + kScene + " --duration 30 --json " + json_path.string() + kNet,
      hapsim::test::temp_path("control-serve.log"));
  ASSERT_TRUE(serve.wait_for("serve        ", std::chrono::seconds(15))) << serve.output();

  Participant participant(kDomain, "control-test");
  LoanedReader<hapsim_msg_ViewState> views(participant);
  TopicReader<hapsim_msg_LocalModel> models(participant);
  LoanedReader<hapsim_msg_SceneInfo> info_in(participant);
  const std::optional<SceneInfoSample> info = wait_for_scene_info(info_in, 10.0);
  ASSERT_TRUE(info.has_value());

  // The first view (discovery and the loop's start take a moment on a loaded machine).
  ASSERT_GT(observe(views, models, 1).views, 0u) << "no view state from serve\n" << serve.output();
  // Running: time goes on.
  const Observed running = observe(views, models, 4);
  ASSERT_GT(running.views, 3u) << serve.output();
  EXPECT_GT(running.last_time_s, running.first_time_s);
  EXPECT_EQ(running.views_paused, 0u);

  const hapsim::test::RunResult pause = hapsim::test::run_hapsim("control pause" + kControl);
  ASSERT_EQ(pause.exit_code, 0) << pause.output << serve.output();
  EXPECT_NE(pause.output.find("is paused"), std::string::npos) << pause.output;
  EXPECT_TRUE(serve.wait_for("command      pause from", std::chrono::seconds(10)));
  drain(views, models);  // what was on the way
  const Observed paused = observe(views, models, 4, 101);
  EXPECT_GT(paused.views, 3u);
  EXPECT_EQ(paused.views_paused, paused.views);
  EXPECT_EQ(paused.last_time_s, paused.first_time_s);  // the world stands still
  EXPECT_GT(paused.models, 100u);                      // still served at the loop's rate...
  EXPECT_EQ(paused.valid_models, 0u);                  // ... as free space: no force

  const hapsim::test::RunResult resume = hapsim::test::run_hapsim("control resume" + kControl);
  ASSERT_EQ(resume.exit_code, 0) << resume.output;
  EXPECT_NE(resume.output.find("is running"), std::string::npos) << resume.output;
  drain(views, models);
  const Observed resumed = observe(views, models, 4);
  EXPECT_GT(resumed.last_time_s, resumed.first_time_s);
  EXPECT_GE(resumed.first_time_s, paused.last_time_s);  // it goes on from where it stood

  const hapsim::test::RunResult reset = hapsim::test::run_hapsim("control reset" + kControl);
  ASSERT_EQ(reset.exit_code, 0) << reset.output;
  drain(views, models);
  const Observed after_reset = observe(views, models, 1);
  EXPECT_LT(after_reset.first_time_s, resumed.last_time_s);  // back at the scene's start
  EXPECT_LT(after_reset.first_time_s, 0.5);

  const hapsim::test::RunResult material = hapsim::test::run_hapsim(
      "control material plastic --stiffness 800 --max-force 6.5" + kControl);
  ASSERT_EQ(material.exit_code, 0) << material.output;
  EXPECT_TRUE(serve.wait_for("plastic to k 800 N/m, max force 6.50 N", std::chrono::seconds(10)))
      << serve.output();
  EXPECT_NE(material.output.find("took the new values"), std::string::npos) << material.output;

  // A value beyond the host's limits: refused, and control says so with the host's reason.
  const hapsim::test::RunResult refused =
      hapsim::test::run_hapsim("control material plastic --stiffness 1e9" + kControl);
  EXPECT_EQ(refused.exit_code, 2) << refused.output;
  EXPECT_NE(refused.output.find("hapsim: control material: the host refused it: out of range: "
                                "stiffness 1e+09 N/m is not within 0 .. 1e+06 N/m"),
            std::string::npos)
      << refused.output;
  EXPECT_EQ(refused.output.find("took the new values"), std::string::npos) << refused.output;
  EXPECT_TRUE(serve.wait_for("stiffness 1e+09 N/m is not within", std::chrono::seconds(10)))
      << serve.output();

  // A command for another start of this host, written by hand: dropped and counted.
  {
    TopicWriter<hapsim_msg_Command> writer(participant);
    for (auto until = Clock::now() + std::chrono::seconds(5);
         writer.matched_readers() == 0 && Clock::now() < until;) {
      std::this_thread::sleep_for(std::chrono::milliseconds(2));
    }
    SessionCommand c;
    c.kind = SessionCommandKind::kPause;
    ASSERT_TRUE(
        writer.write(encode_session_command(c, 42, 1, info->scene_hash, info->serve_id ^ 1U)));
    EXPECT_TRUE(writer.wait_for_acks(5.0));
  }
  EXPECT_TRUE(serve.wait_for("the command was meant for an earlier start of this host",
                             std::chrono::seconds(10)))
      << serve.output();
  drain(views, models);
  const Observed still_running = observe(views, models, 4);
  EXPECT_EQ(still_running.views_paused, 0u);

  // Bad requests: one line, exit 2, before (or without) touching the host.
  const hapsim::test::RunResult typo = hapsim::test::run_hapsim("control pauze" + kControl);
  EXPECT_EQ(typo.exit_code, 2);
  EXPECT_NE(typo.output.find("expected pause, resume, reset or material"), std::string::npos);
  const hapsim::test::RunResult unknown =
      hapsim::test::run_hapsim("control material bone --stiffness 10" + kControl);
  EXPECT_EQ(unknown.exit_code, 2);
  EXPECT_NE(unknown.output.find("has no such material (it has plastic)"), std::string::npos)
      << unknown.output;
  const hapsim::test::RunResult no_values =
      hapsim::test::run_hapsim("control material plastic" + kControl);
  EXPECT_EQ(no_values.exit_code, 2);
  const hapsim::test::RunResult nobody =
      hapsim::test::run_hapsim("control pause --session nobody-here --domain 80 --timeout 0.5");
  EXPECT_EQ(nobody.exit_code, 2);
  EXPECT_NE(nobody.output.find("no simulation host"), std::string::npos);

  // SIGINT: the run stops, its summary and JSON are written, and it exits 128 + 2.
  serve.signal(SIGINT);
  EXPECT_EQ(serve.wait(), 130) << serve.output();
  EXPECT_TRUE(std::regex_search(serve.output(), std::regex("commands     6 received: accepted 4")))
      << serve.output();
  std::ifstream in(json_path);
  const nlohmann::json j = nlohmann::json::parse(in);
  EXPECT_EQ(j["stopped_by"], "SIGINT");
  EXPECT_EQ(j["serve"]["commands"]["accepted"], 4);
  EXPECT_EQ(j["serve"]["commands"]["out of range"], 1);
  EXPECT_EQ(j["serve"]["commands"]["stale"], 1);
  EXPECT_EQ(j["serve"]["refused_material_changes"], 0);
}

}  // namespace
}  // namespace hapsim::net
