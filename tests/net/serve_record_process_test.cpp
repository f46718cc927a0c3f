// `hapsim serve --record FILE` (issue 31): a served session is recorded as `hapsim run --record`
// records one — every stepped cycle, the same writer — so it replays bit for bit and is scored by
// `hapsim assess`. With no device host, serve steps the scene's own script, which is what
// `hapsim run` steps: the served recording must be the one-process recording, byte for byte (the
// independent reference). SIGINT and SIGTERM finish the file; a full disk ends the recording with
// exit 2. With --secure the recording is signed (issue 32): `hapsim assess --verify` scores it,
// and refuses it once a byte is flipped.
#include "hapsim/net/recording_signature.h"

#include "apps/hapsim_process.h"
#include "net/net_test_support.h"
#include "support/small_tmpfs.h"

#include <chrono>
#include <csignal>
#include <fstream>
#include <iterator>
#include <regex>
#include <thread>

#include <gtest/gtest.h>

namespace hapsim::net {
namespace {

namespace fs = std::filesystem;
using hapsim::test::RunResult;

const std::string kScene = std::string(HAPSIM_SOURCE_DIR) + "/scenes/knee_paper.json";
const std::string kPlain = " --domain 86";
const std::string kSecureDomain = " --domain 87";

RunResult run_limited(const std::string& args) {
  return hapsim::test::run_hapsim_env("timeout -s KILL 180", args);
}

std::string contents(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

// A log of its own for each process (with --repeat a reused name would be read before the new
// process truncated it).
fs::path fresh_log(const std::string& name) {
  static int count = 0;
  return hapsim::test::temp_path(name + "-" + std::to_string(++count) + ".log");
}

// The steps serve's summary counts ("3000 steps, ...") and the frames it says it recorded
// ("recorded     FILE (N frames)"); -1 when missing.
long summary_number(const std::string& output, const std::string& pattern) {
  std::smatch m;
  return std::regex_search(output, m, std::regex(pattern)) ? std::stol(m[1].str()) : -1;
}
long steps_of(const std::string& output) {
  return summary_number(output, R"((?:^|\n)([0-9]+) steps, )");
}
long recorded_frames_of(const std::string& output) {
  return summary_number(output, R"(recorded     [^\n]* \(([0-9]+) frames\))");
}

// Waits until `file` holds more than `bytes` (the recorder flushes every 100 ms): the session has
// run a while. A hang's bound only.
bool wait_for_size(const fs::path& file, std::uintmax_t bytes) {
  for (int i = 0; i < 600; ++i) {
    std::error_code ec;
    if (fs::file_size(file, ec) > bytes && !ec) {
      return true;
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(100));
  }
  return false;
}

// The assessment's lines (without the "recording ..." line naming the file).
std::string assessment_lines(const std::string& output) {
  const std::size_t at = output.find("assessment   ");
  return at == std::string::npos ? std::string() : output.substr(at);
}

TEST(ServeRecordProcess, AServedSessionIsTheOneProcessRecordingAndIsReplayedAndAssessed) {
  ASSERT_TRUE(test::on_loopback_config());
  const fs::path served = hapsim::test::temp_path("served.rec");
  const fs::path json = hapsim::test::temp_path("served.json");
  const RunResult serve =
      run_limited("serve " + kScene + " --record " + served.string() + " --duration 2 --json " +
                  json.string() + " --session serve-record" + kPlain);
  ASSERT_EQ(serve.exit_code, 0) << serve.output;
  const long steps = steps_of(serve.output);
  EXPECT_EQ(steps, 2000) << serve.output;
  EXPECT_EQ(recorded_frames_of(serve.output), steps) << serve.output;  // every stepped cycle
  EXPECT_NE(serve.output.find("recorded frames: 2000 (dropped 0)"), std::string::npos)
      << serve.output;
  EXPECT_NE(contents(json).find("\"recording_frames\": 2000"), std::string::npos) << contents(json);

  // The same script in one process, recorded by `hapsim run`: the same bytes.
  const fs::path one = hapsim::test::temp_path("one-process.rec");
  const RunResult run = run_limited("run " + kScene + " -q --duration 2 --record " + one.string());
  ASSERT_EQ(run.exit_code, 0) << run.output;
  EXPECT_TRUE(contents(served) == contents(one))
      << "the served recording differs from the one-process one (" << fs::file_size(served)
      << " vs " << fs::file_size(one) << " bytes)";

  const RunResult replay = run_limited("run " + kScene + " -q --replay " + served.string());
  EXPECT_EQ(replay.exit_code, 0) << replay.output;
  EXPECT_NE(replay.output.find("identical to " + served.string() + ", bit for bit (2000 frames)"),
            std::string::npos)
      << replay.output;

  const RunResult assessed = run_limited("assess " + served.string());
  EXPECT_EQ(assessed.exit_code, 0) << assessed.output;
  EXPECT_NE(assessed.output.find("score        "), std::string::npos) << assessed.output;
  EXPECT_EQ(assessed.output.find("warning"), std::string::npos) << assessed.output;
  const RunResult assessed_one = run_limited("assess " + one.string());
  EXPECT_EQ(assessment_lines(assessed.output), assessment_lines(assessed_one.output));
  EXPECT_FALSE(assessment_lines(assessed.output).empty()) << assessed.output;
}

TEST(ServeRecordProcess, SigtermFinishesTheRecording) {
  ASSERT_TRUE(test::on_loopback_config());
  const fs::path rec = hapsim::test::temp_path("sigterm.rec");
  hapsim::test::BackgroundHapsim serve(
      "serve " + kScene + " --record " + rec.string() + " --session serve-record-term" + kPlain,
      fresh_log("serve-record-term"));
  ASSERT_TRUE(wait_for_size(rec, 300'000)) << serve.output();
  serve.signal(SIGTERM);
  EXPECT_EQ(serve.wait(), 143) << serve.output();
  const long steps = steps_of(serve.output());
  EXPECT_GT(steps, 100) << serve.output();
  EXPECT_EQ(recorded_frames_of(serve.output()), steps) << serve.output();
  // Nothing lost, nothing torn: the replay reads every frame and reproduces it.
  const RunResult replay = run_limited("run " + kScene + " -q --replay " + rec.string());
  EXPECT_EQ(replay.exit_code, 0) << replay.output;
  EXPECT_NE(replay.output.find("bit for bit (" + std::to_string(steps) + " frames)"),
            std::string::npos)
      << replay.output;
  EXPECT_EQ(replay.output.find("not a whole block"), std::string::npos) << replay.output;
}

TEST(ServeRecordProcess, BadRecordOptionsAreOneLineBeforeServing) {
  const RunResult rate =
      run_limited("serve " + kScene + " --record " + hapsim::test::temp_path("r.rec").string() +
                  " --rate 500 --duration 1 --session serve-record-bad" + kPlain);
  EXPECT_EQ(rate.exit_code, 2) << rate.output;
  EXPECT_NE(rate.output.find("a recording replays at the scene's run.dt_s, 0.001 s: serve it at "
                             "--rate 1000, not 500"),
            std::string::npos)
      << rate.output;
  const RunResult path = run_limited("serve " + kScene +
                                     " --record /nonexistent-folder/r.rec --duration 1 --session "
                                     "serve-record-bad" +
                                     kPlain);
  EXPECT_EQ(path.exit_code, 2) << path.output;
  EXPECT_NE(path.output.find("hapsim: --record /nonexistent-folder/r.rec: "), std::string::npos)
      << path.output;
  EXPECT_EQ(path.output.find("serve        "), std::string::npos) << path.output;  // nothing served
}

// A recording that fills the disk ends the recording, not the session: the summary says why,
// serve exits 2, and what was kept replays.
TEST(ServeRecordProcess, AFullDiskEndsTheRecordingWithExit2) {
  ASSERT_TRUE(test::on_loopback_config());
  const hapsim::test::SmallTmpfs disk("serve_rec", 256);
  if (!disk.mounted()) {
    GTEST_SKIP() << disk.why_not();
  }
  const fs::path rec = disk.dir() / "serve.rec";
  const fs::path json = hapsim::test::temp_path("full.json");
  const RunResult serve =
      run_limited("serve " + kScene + " --record " + rec.string() + " --duration 1 --json " +
                  json.string() + " --session serve-record-full" + kPlain);
  EXPECT_EQ(serve.exit_code, 2) << serve.output;
  EXPECT_NE(serve.output.find("recording STOPPED early: "), std::string::npos) << serve.output;
  EXPECT_NE(serve.output.find("FAILED: the recording stopped early"), std::string::npos)
      << serve.output;
  EXPECT_NE(serve.output.find("step cost"), std::string::npos) << serve.output;  // the summary
  EXPECT_NE(contents(json).find("\"ok\": false"), std::string::npos) << contents(json);
  const long kept = recorded_frames_of(serve.output);
  EXPECT_GT(kept, 0) << serve.output;
  EXPECT_LT(kept, 1000) << serve.output;
  const RunResult replay = run_limited("run " + kScene + " -q --replay " + rec.string());
  EXPECT_EQ(replay.exit_code, 0) << replay.output;
  EXPECT_NE(replay.output.find("bit for bit (" + std::to_string(kept) + " frames)"),
            std::string::npos)
      << replay.output;
}

TEST(ServeRecordProcess, ASecureServeSignsItsRecordingAndAssessVerifiesIt) {
  ASSERT_TRUE(test::on_loopback_config());
  const std::string session = "signed-rec";
  const fs::path keys = hapsim::test::temp_path("keys");
  fs::remove_all(keys);
  (void)SecurityKeyDir::init(keys, session, {"rig1"});
  const fs::path rec = hapsim::test::temp_path("signed.rec");
  const std::string net = " --session " + session + kSecureDomain + " --secure " + keys.string();
  hapsim::test::BackgroundHapsim serve("serve " + kScene + " --record " + rec.string() + net,
                                       fresh_log("serve-signed"));
  ASSERT_TRUE(wait_for_size(rec, 300'000)) << serve.output();
  serve.signal(SIGINT);  // a session ended by Ctrl-C is signed too
  EXPECT_EQ(serve.wait(), 130) << serve.output();
  EXPECT_NE(serve.output().find("security     SECURE"), std::string::npos) << serve.output();
  EXPECT_NE(serve.output().find("signed       " + rec.string() +
                                ".sig (identity 'serve' of "
                                "session '" +
                                session + "'"),
            std::string::npos)
      << serve.output();

  const RunResult verified =
      run_limited("assess --verify --secure " + keys.string() + " " + rec.string());
  EXPECT_EQ(verified.exit_code, 0) << verified.output;
  EXPECT_NE(verified.output.find("verified     " + rec.string() +
                                 ": signed by serve identity 'serve' of session '" + session + "'"),
            std::string::npos)
      << verified.output;
  EXPECT_NE(verified.output.find("a device host drove 0 of its " +
                                 std::to_string(steps_of(serve.output())) + " cycles"),
            std::string::npos)
      << verified.output << serve.output();
  EXPECT_NE(verified.output.find("score        "), std::string::npos) << verified.output;
  // The key directory from the environment, as every secure command takes it.
  const RunResult from_env =
      hapsim::test::run_hapsim_env("timeout -s KILL 180 env HAPSIM_SECURE_DIR=" + keys.string(),
                                   "assess --verify " + rec.string());
  EXPECT_EQ(from_env.exit_code, 0) << from_env.output;

  // One byte flipped: refused with one line, nothing scored.
  std::string bytes = contents(rec);
  bytes[bytes.size() / 3] = static_cast<char>(bytes[bytes.size() / 3] ^ 0x20);
  std::ofstream(rec, std::ios::binary | std::ios::trunc) << bytes;
  const RunResult refused =
      run_limited("assess --verify --secure " + keys.string() + " " + rec.string());
  EXPECT_EQ(refused.exit_code, 2) << refused.output;
  EXPECT_NE(refused.output.find("hapsim: refused: " + rec.string() +
                                ": its SHA-256 digest does not match the signature's"),
            std::string::npos)
      << refused.output;
  EXPECT_EQ(refused.output.find("score"), std::string::npos) << refused.output;
  // A scripted `hapsim run` recording has no signature: refused before it is scored.
  const RunResult unsigned_run = run_limited("run " + kScene + " -q --duration 0.5 --record " +
                                             hapsim::test::temp_path("scripted.rec").string());
  ASSERT_EQ(unsigned_run.exit_code, 0) << unsigned_run.output;
  const RunResult scripted = run_limited("assess --verify --secure " + keys.string() + " " +
                                         hapsim::test::temp_path("scripted.rec").string());
  EXPECT_EQ(scripted.exit_code, 2) << scripted.output;
  EXPECT_NE(scripted.output.find(".sig is not there"), std::string::npos) << scripted.output;
}

}  // namespace
}  // namespace hapsim::net
