// Faults around the real `hapsim run` (issue 14 item 3): the real-time process stopped for 2 s
// (SIGSTOP) and continued, and the disk filling up while a run records. Expected: the run goes on
// and exits cleanly (its summary counts the gap the haptic thread ramped), or, when the disk
// fills, the recording stops and the run goes on to its end, then says why, naming the file, and
// exits 2; nothing recorded before the fault is lost (the recording reads and replays bit for bit
// up to it). The disk is "full" through the file size limit (ulimit -f, SIGXFSZ
// ignored), which fails a write past it with EFBIG as a full disk fails it with ENOSPC.
#include "hapsim_process.h"

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <chrono>
#include <csignal>
#include <filesystem>
#include <fstream>
#include <regex>
#include <string>
#include <thread>

namespace {

namespace fs = std::filesystem;
using hapsim::test::BackgroundHapsim;
using hapsim::test::RunResult;

const std::string kKnee = std::string(HAPSIM_SCENES_DIR) + "/knee_procedural.json";

// `hapsim ARGS` with files limited to `kib` KiB; a hang is killed after 120 s.
RunResult run_with_file_limit(int kib, const std::string& args) {
  return hapsim::test::run_hapsim_env("timeout -s KILL 120 bash -c 'trap \"\" XFSZ; ulimit -f " +
                                          std::to_string(kib) + "; exec \"$0\" \"$@\"'",
                                      args);
}

// The summary's "recording STOPPED early: PATH: write failed (disk full?): the recording keeps
// its first K frame(s)..." line; K (-1 when the line is missing).
long kept_frames(const RunResult& r, const fs::path& recording) {
  const std::regex line("recording STOPPED early: " + recording.string() +
                        ": write failed \\(disk full\\?\\): the recording keeps its first "
                        "([0-9]+) frame");
  std::smatch m;
  return std::regex_search(r.output, m, line) ? std::stol(m[1]) : -1;
}

// The recording `kept` frames long replays bit for bit through `hapsim run --replay`.
void expect_replays(const fs::path& recording, long kept) {
  const RunResult replay =
      hapsim::test::run_hapsim("run " + kKnee + " -q --replay " + recording.string());
  EXPECT_EQ(replay.exit_code, 0) << replay.output;
  EXPECT_NE(replay.output.find("identical to " + recording.string() + ", bit for bit (" +
                               std::to_string(kept) + " frames)"),
            std::string::npos)
      << replay.output;
}

TEST(RealtimeFaults, DiskFullWhileRecordingKeepsEveryFrameBeforeIt) {
  const fs::path recording = hapsim::test::temp_path("full_disk.rec");
  const RunResult r =
      run_with_file_limit(256, "run " + kKnee + " -q --duration 2 --record " + recording.string());
  EXPECT_EQ(r.exit_code, 2) << r.output;
  const long kept = kept_frames(r, recording);
  ASSERT_GT(kept, 0) << r.output;
  EXPECT_EQ(r.output.find("internal error"), std::string::npos) << r.output;
  expect_replays(recording, kept);
}

TEST(RealtimeFaults, DiskFullWhileRecordingInRealTimeStopsCleanlyAndKeepsTheFrames) {
  const fs::path recording = hapsim::test::temp_path("full_disk_rt.rec");
  const RunResult r = run_with_file_limit(
      256, "run " + kKnee + " -q --realtime --duration 3 --record " + recording.string());
  EXPECT_EQ(r.exit_code, 2) << r.output;
  const long kept = kept_frames(r, recording);
  ASSERT_GT(kept, 0) << r.output;
  expect_replays(recording, kept);
}

// The real-time run stopped 2 s and continued: it finishes its cycles, exits 0, reports the gap
// its haptic thread ramped, and its recording replays bit for bit (the recording holds the world's
// commands; the ramp is the loop's).
TEST(RealtimeFaults, RunStoppedTwoSecondsGoesOnAndRampsTheGap) {
  const fs::path json = hapsim::test::temp_path("stopped.json");
  const fs::path recording = hapsim::test::temp_path("stopped.rec");
  const fs::path log = hapsim::test::temp_path("stopped.log");
  BackgroundHapsim run("run " + kKnee + " --realtime --duration 3 --json " + json.string() +
                           " --record " + recording.string(),
                       log);
  // The progress line says the loop is running (not still loading the scene).
  ASSERT_TRUE(run.wait_for("run (real time)", std::chrono::seconds(60))) << run.output();
  run.signal(SIGSTOP);
  std::this_thread::sleep_for(std::chrono::seconds(2));
  run.signal(SIGCONT);
  ASSERT_EQ(run.wait(), 0) << run.output();
  std::ifstream in(json);
  const nlohmann::json j = nlohmann::json::parse(in);
  EXPECT_GE(j["realtime"]["resume_gaps"].get<int>(), 1) << j["realtime"].dump();
  EXPECT_EQ(j["nonfinite_commands"].get<int>(), 0);
  EXPECT_EQ(j["max_force_limit_violations"].get<int>(), 0);
  EXPECT_EQ(j["steps"].get<int>(), 3000);
  expect_replays(recording, 3000);
}

}  // namespace
