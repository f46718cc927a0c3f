// `hapsim run --replay` and `hapsim assess` read a recording frame by frame: their peak memory
// does not grow with the file's length. A 200 MB recording (two minutes of a press scene) is made
// here, then replayed and assessed in child processes whose peak resident set (wait4's
// ru_maxrss) must stay under 100 MB. Before streaming, a replay held every frame: about 230 MB
// for this file. (By hand, a 1 GB recording: docs/recording-format.md, "Reading".)
#include "hapsim/device/recording.h"

#include "hapsim_process.h"

#include <fcntl.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

namespace {

namespace fs = std::filesystem;
using hapsim::test::run_hapsim;
using hapsim::test::RunResult;
using hapsim::test::temp_path;
using hapsim::test::write_file;

constexpr double kSessionS = 125.0;  // 125,000 frames of about 1.7 kB: about 210 MB

struct ChildRun {
  int exit_code = -1;
  long peak_rss_kb = -1;
  std::string output;
};

// `hapsim ARGS` in a child process: its exit status, its own peak resident set and its output.
ChildRun run_measured(const std::vector<std::string>& args, const fs::path& log) {
  std::vector<std::string> words{HAPSIM_BIN_PATH};
  words.insert(words.end(), args.begin(), args.end());
  const pid_t pid = hapsim::test::spawn_logged(std::move(words), log);
  ChildRun run;
  int status = 0;
  rusage usage{};
  if (::wait4(pid, &status, 0, &usage) == pid) {
    run.exit_code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
    run.peak_rss_kb = usage.ru_maxrss;
  }
  std::ifstream in(log);
  std::stringstream text;
  text << in.rdbuf();
  run.output = text.str();
  return run;
}

TEST(StreamingReaders, ReplayAndAssessOfA200MBRecordingStayUnder100MB) {
  // A press every 8 s for the whole session, with an assessment to score.
  std::string csv = "t,x,y,z,qw,qx,qy,qz\n";
  for (int press = 0; press * 8.0 <= kSessionS; ++press) {
    const double t = press * 8.0;
    csv += std::to_string(t) + ",0,0,0.065,1,0,0,0\n" + std::to_string(t + 4.0) +
           ",0,0,0.025,1,0,0,0\n";
  }
  const fs::path trajectory = write_file("streaming.csv", csv);
  const fs::path scene = write_file("streaming.json", R"({
    "format": "hapsim-scene/1",
    "materials": { "gel": { "response": "penalty", "stiffness_n_per_m": 300,
                            "max_penetration_m": 0.05, "max_force_n": 100 } },
    "bodies": [ { "name": "ball", "geometry": { "sphere": { "radius_m": 0.05 } },
                  "materials": "gel" } ],
    "tools": [ { "name": "tip", "radius_m": 0.005 } ],
    "device": { "profile": "omega3", "trajectory": ")" + trajectory.string() +
                                                          R"(" },
    "run": { "duration_s": )" + std::to_string(kSessionS) +
                                                          R"( },
    "assessment": {
      "landmarks": [ { "name": "top", "segment": "ball", "point_m": [0, 0, 0.05],
                       "radius_m": 0.002, "force_n": 1.0 } ],
      "limits": [ { "segment": "ball", "max_force_n": 5.0 } ]
    }
  })");
  const fs::path recording = temp_path("streaming.rec");
  const RunResult made = run_hapsim("run " + scene.string() + " -q --record " + recording.string());
  ASSERT_EQ(made.exit_code, 0) << made.output;
  const auto frames = static_cast<std::size_t>(kSessionS * 1000.0 + 0.5);
  ASSERT_GE(fs::file_size(recording), frames * hapsim::recorded_frame_payload_bytes());
  ASSERT_GE(fs::file_size(recording), 200'000'000u);

  const ChildRun replay =
      run_measured({"run", scene.string(), "-q", "--replay", recording.string()},
                   temp_path("streaming_replay.log"));
  EXPECT_EQ(replay.exit_code, 0) << replay.output;
  EXPECT_NE(replay.output.find("bit for bit (" + std::to_string(frames) + " frames)"),
            std::string::npos)
      << replay.output;
  EXPECT_LT(replay.peak_rss_kb, 100 * 1024) << "replay peak RSS " << replay.peak_rss_kb << " kB";

  const ChildRun assess =
      run_measured({"assess", recording.string()}, temp_path("streaming_assess.log"));
  EXPECT_EQ(assess.exit_code, 0) << assess.output;
  EXPECT_NE(assess.output.find("(" + std::to_string(frames) + " frames)"), std::string::npos)
      << assess.output;
  EXPECT_LT(assess.peak_rss_kb, 100 * 1024) << "assess peak RSS " << assess.peak_rss_kb << " kB";
  std::printf("peak RSS: replay %ld kB, assess %ld kB, of a %ju-byte recording\n",
              replay.peak_rss_kb, assess.peak_rss_kb,
              static_cast<std::uintmax_t>(fs::file_size(recording)));
  fs::remove(recording);
}

}  // namespace
