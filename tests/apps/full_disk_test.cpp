// Every command that writes a file, on a full disk (issue 31): exit 2 and one line naming the
// option and the path, no "wrote"/success line for it, and the old file (if any) left whole. Two
// full disks: /dev/full (every write fails at once; written in place, never replaced) and a 64 KiB
// tmpfs (fills after some bytes, as a real disk does; needs root to mount, else the test skips).
#include "hapsim_process.h"
#include "support/small_tmpfs.h"

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>

namespace {

namespace fs = std::filesystem;
using hapsim::test::RunResult;

const std::string kScenes = std::string(HAPSIM_SCENES_DIR) + "/";
const fs::path kSource = fs::path(HAPSIM_SOURCE_DIR);

RunResult run_limited(const std::string& args) {
  return hapsim::test::run_hapsim_env("timeout -s KILL 120", args);
}

std::size_t count_lines_starting(const std::string& text, const std::string& prefix) {
  std::size_t n = text.rfind(prefix, 0) == 0 ? 1 : 0;
  for (std::size_t at = text.find('\n' + prefix); at != std::string::npos;
       at = text.find('\n' + prefix, at + 1)) {
    ++n;
  }
  return n;
}

// Exit 2, exactly one "hapsim: " line, containing `option PATH` and the disk's reason.
void expect_full_disk_line(const RunResult& r, const std::string& option, const fs::path& path) {
  EXPECT_EQ(r.exit_code, 2) << r.output;
  EXPECT_EQ(count_lines_starting(r.output, "hapsim: "), 1u) << r.output;
  EXPECT_NE(r.output.find("hapsim: " + option + " " + path.string() + ": "), std::string::npos)
      << r.output;
  EXPECT_NE(r.output.find("No space left on device"), std::string::npos) << r.output;
  EXPECT_EQ(r.output.find("wrote        " + path.string()), std::string::npos) << r.output;
  EXPECT_EQ(r.output.find("internal error"), std::string::npos) << r.output;
}

std::string contents(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

class FullDisk : public ::testing::Test {
 protected:
  void SetUp() override {
    if (!fs::exists("/dev/full")) {
      GTEST_SKIP() << "no /dev/full on this system";
    }
  }
};

TEST_F(FullDisk, DevFullFailsEveryJsonAndCsvWriter) {
  const fs::path full("/dev/full");
  const fs::path points = hapsim::test::write_file("full_points.csv", "0,0,0\n");
  const fs::path joints = hapsim::test::write_file("full_joints.csv", "0,0,0,0,0,0\n");
  const std::string gp7 = (kSource / "fuzz/corpus/urdf/gp7.urdf").string();
  expect_full_disk_line(run_limited("info builtin:box --json /dev/full"), "--json", full);
  expect_full_disk_line(
      run_limited("query builtin:box --points " + points.string() + " --out /dev/full"), "--out",
      full);
  expect_full_disk_line(
      run_limited("query builtin:box --points " + points.string() + " --json /dev/full"), "--json",
      full);
  expect_full_disk_line(
      run_limited("fk " + gp7 + " --joints " + joints.string() + " --out /dev/full"), "--out",
      full);
  expect_full_disk_line(
      run_limited("sheet-profile " + kScenes + "teleop.json --force 1.5 --out /dev/full"), "--out",
      full);
  const fs::path glove = kSource / "examples" / "glove_calibration";
  expect_full_disk_line(
      run_limited("calibrate glove " + (glove / "raw_procedure.csv").string() + " --procedure " +
                  (glove / "procedure.json").string() + " --out /dev/full"),
      "--out", full);
  expect_full_disk_line(
      run_limited("bench soak --scenes " + kScenes + "teleop.json --minutes 0.1 --json /dev/full"),
      "--json", full);
  EXPECT_TRUE(fs::is_character_file(full));  // written in place, never renamed over
}

TEST(FullTmpfs, MeshWritersFailAndKeepTheOldFile) {
  const hapsim::test::SmallTmpfs disk("apps_mesh");
  if (!disk.mounted()) {
    GTEST_SKIP() << disk.why_not();
  }
  // A mesh of about a megabyte: far more than the 64 KiB disk holds.
  const fs::path poly = disk.dir() / "poly.stl";
  { std::ofstream(poly) << "old"; }
  expect_full_disk_line(
      run_limited("polygonize --mesh builtin:bumpy-sphere --cell-m 0.004 --out " + poly.string()),
      "--out", poly);
  EXPECT_EQ(contents(poly), "old");  // the user's file is untouched
  const fs::path simple = disk.dir() / "simple.obj";
  expect_full_disk_line(
      run_limited("simplify builtin:bumpy-sphere --target-vertices 3000 --out " + simple.string()),
      "--out", simple);
  EXPECT_FALSE(fs::exists(simple));
  // Only what was there before: no temporaries left behind.
  EXPECT_EQ(std::distance(fs::directory_iterator(disk.dir()), fs::directory_iterator()), 1);
}

TEST(FullTmpfs, TetrahedralizeFailsAndLeavesNoHalfPair) {
  const hapsim::test::SmallTmpfs disk("apps_tet");
  if (!disk.mounted()) {
    GTEST_SKIP() << disk.why_not();
  }
  if (run_limited("tetrahedralize --help").exit_code != 0 ||
      std::system("command -v tetgen > /dev/null 2>&1") != 0) {
    GTEST_SKIP() << "tetgen is not installed";
  }
  const fs::path skin = hapsim::test::temp_path("tet_skin.stl");
  ASSERT_EQ(
      run_limited("polygonize --mesh builtin:bumpy-sphere --cell-m 0.01 --out " + skin.string())
          .exit_code,
      0);
  const fs::path prefix = disk.dir() / "body";
  const RunResult r =
      run_limited("tetrahedralize --outer " + skin.string() + " --out " + prefix.string());
  EXPECT_EQ(r.exit_code, 2) << r.output;
  EXPECT_EQ(count_lines_starting(r.output, "hapsim: "), 1u) << r.output;
  EXPECT_NE(r.output.find("hapsim: --out: " + prefix.string()), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("No space left on device"), std::string::npos) << r.output;
  EXPECT_FALSE(fs::exists(prefix.string() + ".node"));
  EXPECT_FALSE(fs::exists(prefix.string() + ".ele"));
}

TEST(FullTmpfs, CsvAndJsonWritersFailPartWay) {
  const hapsim::test::SmallTmpfs disk("apps_csv");
  if (!disk.mounted()) {
    GTEST_SKIP() << disk.why_not();
  }
  // 4,000 points: a CSV of about 500 KB.
  std::string many;
  for (int i = 0; i < 4000; ++i) {
    many += std::to_string(i * 1e-5) + ",0.001,0.002\n";
  }
  const fs::path points = hapsim::test::write_file("full_many_points.csv", many);
  const fs::path csv = disk.dir() / "closest.csv";
  expect_full_disk_line(
      run_limited("query builtin:box --points " + points.string() + " --out " + csv.string()),
      "--out", csv);
  EXPECT_FALSE(fs::exists(csv));
  const fs::path profile = disk.dir() / "profile.csv";
  expect_full_disk_line(
      run_limited("sheet-profile " + kScenes +
                  "teleop.json --force 1,2,3,4,5,6,7,8,9,10,11,12,13,14,15,16 --out " +
                  profile.string()),
      "--out", profile);
  EXPECT_EQ(std::distance(fs::directory_iterator(disk.dir()), fs::directory_iterator()), 0);
}

// A recording that fills the disk ends the recording, not the run: the run goes on to its end,
// prints its summary with the reason, writes its --json (elsewhere) with ok false and the
// recording's error, and exits 2; the file keeps its complete blocks and reads back.
TEST(FullTmpfs, ARecordingThatFillsTheDiskStillGivesTheSummaryAndTheJson) {
  const hapsim::test::SmallTmpfs disk("apps_rec");
  if (!disk.mounted()) {
    GTEST_SKIP() << disk.why_not();
  }
  const fs::path rec = disk.dir() / "run.rec";
  const fs::path json = hapsim::test::temp_path("full_disk_run.json");
  const RunResult r = run_limited("run " + kScenes + "csg_block.json -q --record " + rec.string() +
                                  " --json " + json.string());
  EXPECT_EQ(r.exit_code, 2) << r.output;
  EXPECT_NE(r.output.find("recording STOPPED early: "), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("FAILED: the recording stopped early"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("step cost"), std::string::npos) << r.output;  // the whole summary
  EXPECT_EQ(r.output.find("internal error"), std::string::npos) << r.output;
  const std::string written = contents(json);
  EXPECT_NE(written.find("\"ok\": false"), std::string::npos) << written;
  EXPECT_NE(written.find("\"recording_error\""), std::string::npos) << written;
  EXPECT_NE(written.find("\"steps\""), std::string::npos) << written;
  // What the recording kept is readable: its complete blocks.
  const RunResult replay =
      run_limited("run " + kScenes + "csg_block.json -q --replay " + rec.string());
  EXPECT_EQ(replay.output.find("internal error"), std::string::npos) << replay.output;
  EXPECT_EQ(replay.output.find("corrupt"), std::string::npos) << replay.output;
}

}  // namespace
