// `hapsim run --realtime --record` cut short, as a trainee's session ends: killed outright
// (kill -9), the recording keeps every block written before (flushed every 100 ms off the haptic
// thread), replays bit for bit and assesses; stopped with SIGINT or SIGTERM, the run writes its
// summary, its JSON (saying it was interrupted) and the recording's end, and exits 130 / 143.
// Progress-based: each test waits for the recording to hold enough frames, never a fixed sleep,
// so a loaded machine (stress-ng beside the tests) only makes them slower.
#include "hapsim/device/recording.h"

#include <nlohmann/json.hpp>

#include "hapsim_process.h"

#include <gtest/gtest.h>

#include <chrono>
#include <csignal>
#include <filesystem>
#include <fstream>
#include <string>
#include <thread>

namespace {

namespace fs = std::filesystem;
using hapsim::test::BackgroundHapsim;
using hapsim::test::run_hapsim;
using hapsim::test::RunResult;
using hapsim::test::temp_path;
using hapsim::test::write_file;

// A probe pressing a 50 mm sphere 30 mm deep and back over 8 s, with landmarks to assess (as in
// assess_command_test.cpp): cheap to step, so the real-time loop keeps up on a loaded machine.
fs::path press_scene(const std::string& name) {
  const fs::path csv = write_file(name + ".csv",
                                  "t,x,y,z,qw,qx,qy,qz\n0,0,0,0.065,1,0,0,0\n4,0,0,0.025,1,0,0,0\n"
                                  "8,0,0,0.065,1,0,0,0\n");
  return write_file(name + ".json", R"({
    "format": "hapsim-scene/1",
    "world": { "passivity_damping_factor": 0 },
    "materials": { "gel": { "response": "penalty", "stiffness_n_per_m": 300,
                            "max_penetration_m": 0.05, "max_force_n": 100 } },
    "bodies": [ { "name": "ball", "geometry": { "sphere": { "radius_m": 0.05 } },
                  "materials": "gel" } ],
    "tools": [ { "name": "tip", "radius_m": 0.005 } ],
    "device": { "profile": "omega3", "trajectory": ")" +
                                        csv.string() +
                                        R"(" },
    "run": { "duration_s": 8.0 },
    "assessment": {
      "landmarks": [ { "name": "top", "segment": "ball", "point_m": [0, 0, 0.05],
                       "radius_m": 0.002, "force_n": 1.0, "dwell_s": 0.5 } ],
      "limits": [ { "segment": "ball", "max_force_n": 3.0015 } ]
    }
  })");
}

// Frames the recording at `path` holds on disk now (whole blocks: its size past the header).
std::size_t frames_on_disk(const fs::path& path) {
  std::error_code ec;
  const auto size = fs::file_size(path, ec);
  const std::size_t frame = hapsim::recorded_frame_payload_bytes() + 1;  // + block overhead
  return ec || size < 200 ? 0 : static_cast<std::size_t>((size - 200) / frame);
}

// Waits until `path` holds at least `frames` frames (the run's own progress); false after
// `timeout` or when the process has ended.
bool wait_for_frames(const fs::path& path, std::size_t frames, std::chrono::seconds timeout) {
  const auto give_up = std::chrono::steady_clock::now() + timeout;
  while (std::chrono::steady_clock::now() < give_up) {
    if (frames_on_disk(path) >= frames) {
      return true;
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  }
  return false;
}

// kill -9 three seconds into a real-time recorded run: the recording reads back at least 2,800
// frames (all but the last 100 ms at most), replays them bit for bit and assesses.
TEST(RunInterrupted, KilledRealtimeRecordingReadsReplaysAndAssesses) {
  const fs::path scene = press_scene("interrupt_kill");
  const fs::path recording = temp_path("interrupt_kill.rec");
  fs::remove(recording);  // a repeat (--gtest_repeat) must not find the last one's file
  BackgroundHapsim run("run " + scene.string() + " --realtime -q --record " + recording.string(),
                       temp_path("interrupt_kill.log"));
  ASSERT_TRUE(wait_for_frames(recording, 2900, std::chrono::seconds(120))) << run.output();
  run.signal(SIGKILL);
  EXPECT_EQ(run.wait(), -1);  // killed: no exit status

  hapsim::RecordingReader reader(recording, hapsim::RecordingReader::TornEnd::kQuiet);
  hapsim::RecordedFrame frame;
  std::size_t frames = 0;
  while (reader.next(frame)) {
    EXPECT_EQ(frame.cycle_index, frames);
    ++frames;
  }
  EXPECT_GE(frames, 2800u);
  EXPECT_LT(frames, 8000u);  // the run was cut short

  const RunResult replay =
      run_hapsim("run " + scene.string() + " -q --replay " + recording.string());
  EXPECT_EQ(replay.exit_code, 0) << replay.output;
  EXPECT_NE(replay.output.find("bit for bit (" + std::to_string(frames) + " frames)"),
            std::string::npos)
      << replay.output;

  const fs::path json = temp_path("interrupt_kill_assessment.json");
  const RunResult assess = run_hapsim("assess " + recording.string() + " --json " + json.string());
  EXPECT_EQ(assess.exit_code, 0) << assess.output;
  EXPECT_NE(assess.output.find("(" + std::to_string(frames) + " frames)"), std::string::npos)
      << assess.output;
  EXPECT_EQ(assess.output.find("differs"), std::string::npos) << assess.output;
  std::ifstream in(json);
  const nlohmann::json j = nlohmann::json::parse(in);
  EXPECT_EQ(j.at("schema"), "hapsim.assessment/1");
}

// SIGINT (Ctrl-C) or SIGTERM three seconds in: the run stops, prints its summary, writes the JSON
// (interrupted) and the recording's end (every frame run, no torn end), and exits 128 + signal.
void stop_with(int signal, const std::string& name, int expected_exit) {
  const fs::path scene = press_scene("interrupt_" + name);
  const fs::path recording = temp_path("interrupt_" + name + ".rec");
  const fs::path json = temp_path("interrupt_" + name + "_summary.json");
  fs::remove(recording);  // a repeat (--gtest_repeat) must not find the last one's files
  fs::remove(json);
  BackgroundHapsim run("run " + scene.string() + " --realtime -q --record " + recording.string() +
                           " --json " + json.string(),
                       temp_path("interrupt_" + name + ".log"));
  ASSERT_TRUE(wait_for_frames(recording, 2900, std::chrono::seconds(120))) << run.output();
  run.signal(signal);
  EXPECT_EQ(run.wait(), expected_exit) << run.output();
  const std::string output = run.output();
  EXPECT_NE(output.find("interrupted  by " + name), std::string::npos) << output;
  EXPECT_NE(output.find("recorded frames:"), std::string::npos) << output;  // the summary
  EXPECT_NE(output.find("wrote        " + json.string()), std::string::npos) << output;

  std::ifstream in(json);
  ASSERT_TRUE(in) << output;
  const nlohmann::json j = nlohmann::json::parse(in);
  EXPECT_EQ(j.at("interrupted"), true);
  EXPECT_EQ(j.at("stopped_by"), name);
  const auto recorded = j.at("recorded_frames").get<std::size_t>();
  EXPECT_GE(recorded, 2900u);
  EXPECT_LT(recorded, 8000u);

  hapsim::RecordingReader reader(recording, hapsim::RecordingReader::TornEnd::kQuiet);
  hapsim::RecordedFrame frame;
  std::size_t frames = 0;
  while (reader.next(frame)) {
    ++frames;
  }
  EXPECT_EQ(reader.torn_bytes(), 0u);  // the recording's end was written
  EXPECT_EQ(frames, recorded);
}

TEST(RunInterrupted, SigintWritesSummaryJsonAndRecordingAndExits130) {
  stop_with(SIGINT, "SIGINT", 130);
}

TEST(RunInterrupted, SigtermWritesSummaryJsonAndRecordingAndExits143) {
  stop_with(SIGTERM, "SIGTERM", 143);
}

}  // namespace
