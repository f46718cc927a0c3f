// Hostile input to the real `hapsim` binary (issue 14): each case once crashed, hung, ended in
// "internal error" or passed silently. Now each must end with exit status 2 and one line naming
// the input and the place in it, within a time limit (`timeout` kills a hang: exit 124).
#include "hapsim_process.h"

#include <gtest/gtest.h>

#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <string>

namespace {

namespace fs = std::filesystem;
using hapsim::test::RunResult;

const std::string kHostile = std::string(HAPSIM_SOURCE_DIR) + "/tests/data/hostile/";
const std::string kScenes = std::string(HAPSIM_SCENES_DIR) + "/";

// `hapsim ARGS`, killed after 60 s (a hang must fail the test, not the suite).
RunResult run_limited(const std::string& args) {
  return hapsim::test::run_hapsim_env("timeout -s KILL 60", args);
}

// Exit 2 and one error line, the last one, "hapsim: ..." containing every `needle` (what came
// before it is the command's ordinary progress and report).
void expect_one_line_error(const RunResult& r, std::initializer_list<std::string> needles) {
  EXPECT_EQ(r.exit_code, 2) << r.output;
  std::string text = r.output;
  while (!text.empty() && text.back() == '\n') {
    text.pop_back();
  }
  const std::string last =
      text.substr(text.rfind('\n') == std::string::npos ? 0 : text.rfind('\n') + 1);
  EXPECT_EQ(last.rfind("hapsim: ", 0), 0U) << r.output;
  std::size_t error_lines = last.rfind("hapsim: ", 0) == 0 ? 1 : 0;
  for (std::size_t at = text.find("\nhapsim: "); at != std::string::npos;
       at = text.find("\nhapsim: ", at + 1)) {
    error_lines += at + 1 == text.size() - last.size() ? 0 : 1;
  }
  EXPECT_EQ(error_lines, 1U) << r.output;
  EXPECT_EQ(r.output.find("internal error"), std::string::npos) << r.output;
  for (const std::string& needle : needles) {
    EXPECT_NE(last.find(needle), std::string::npos) << "missing '" << needle << "' in\n"
                                                    << r.output;
  }
}

fs::path write(const std::string& name, const std::string& text) {
  return hapsim::test::write_file(name, text);
}

// A valid scene (the shipped knee) with `replace` put in for `find`.
fs::path knee_with(const std::string& name, const std::string& find, const std::string& replace) {
  std::ifstream in(kScenes + "knee_procedural.json");
  std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  const std::size_t at = text.find(find);
  EXPECT_NE(at, std::string::npos) << find;
  text.replace(at, find.size(), replace);
  return write(name, text);
}

TEST(HostileInput, SceneNestedFiftyThousandDeepIsRefusedAtItsPointer) {
  const std::size_t depth = 50000;
  const fs::path scene = write(
      "deep_scene.json", "{\"format\": \"hapsim-scene/1\", \"bodies\": " + std::string(depth, '[') +
                             std::string(depth, ']') + "}");
  expect_one_line_error(run_limited("run " + scene.string()),
                        {scene.string() + ":/bodies/0/0/0", "nested deeper than 100"});
}

TEST(HostileInput, NumberBeyondADoubleNamesFileAndPointer) {
  const fs::path scene = write(
      "overflow_scene.json", "{\"format\": \"hapsim-scene/1\", \"run\": {\"duration_s\": 1e400}}");
  expect_one_line_error(run_limited("run " + scene.string()),
                        {scene.string() + ":/run/duration_s", "1e400", "beyond the range"});
  const fs::path in_array =
      write("overflow_array.json", "{\"format\": \"hapsim-scene/1\", \"a\": [1, 2, -1e999]}");
  expect_one_line_error(run_limited("run " + in_array.string()), {in_array.string() + ":/a/2"});
}

TEST(HostileInput, BodyFarAwayIsRefused) {
  const fs::path far = knee_with("far_knee.json", "\"position_m\": [0.0, 0.0, 0.0]",
                                 "\"position_m\": [1e300, 0, 0]");
  expect_one_line_error(run_limited("run " + far.string() + " --duration 0.01"),
                        {far.string() + ":/bodies/0/pose/position_m/0", "within 1e6 m"});
}

TEST(HostileInput, UrdfNestedDeepIsRefusedBeforeTinyXml) {
  const std::size_t depth = 50000;
  std::string xml = "<robot name=\"r\">";
  for (std::size_t i = 0; i < depth; ++i) {
    xml += "<a>";
  }
  for (std::size_t i = 0; i < depth; ++i) {
    xml += "</a>";
  }
  xml += "</robot>";
  const fs::path urdf = write("deep.urdf", xml);
  expect_one_line_error(
      run_limited("fk " + urdf.string() + " --joints " + kHostile + "one_joint.csv"),
      {urdf.string() + ":1:", "nested deeper than 64"});
}

TEST(HostileInput, UrdfTruncatedUtf8IsRefusedBeforeTinyXml) {
  const std::string urdf = kHostile + "truncated_utf8.urdf";
  expect_one_line_error(run_limited("fk " + urdf + " --joints " + kHostile + "one_joint.csv"),
                        {urdf + ":1:", "not UTF-8"});
}

TEST(HostileInput, UrdfJointWithItsOwnLinkAsParentAndChildDoesNotHang) {
  const std::string urdf = kHostile + "self_parent_joint.urdf";
  expect_one_line_error(run_limited("fk " + urdf + " --joints " + kHostile + "one_joint.csv"),
                        {urdf, "joint 'wrist'", "link 'arm'", "both its parent and its child"});
  const std::string loop = kHostile + "two_link_loop.urdf";
  expect_one_line_error(run_limited("fk " + loop + " --joints " + kHostile + "one_joint.csv"),
                        {loop, "link 'a'", "child of two joints"});
}

TEST(HostileInput, MalformedPlyIsOneLineNamingTheFile) {
  for (const char* name :
       {"ply_bad_end_header.ply", "ply_binary_bad_end_header.ply", "ply_triangulation.ply"}) {
    const std::string ply = kHostile + name;
    expect_one_line_error(run_limited("info " + ply), {ply + ": "});
  }
}

TEST(HostileInput, FileSystemRefusalsNameThePath) {
  // A symlink loop, a name longer than the file system allows.
  const fs::path loop = hapsim::test::temp_path("loop.stl");
  fs::remove(loop);
  fs::create_symlink(loop, loop);
  expect_one_line_error(run_limited("info " + loop.string()),
                        {loop.string(), "Too many levels of symbolic links"});
  expect_one_line_error(run_limited("run " + loop.string()), {loop.string()});
  const std::string long_name = "/tmp/" + std::string(300, 'k') + ".json";
  expect_one_line_error(run_limited("run " + long_name), {long_name.substr(0, 40)});
  expect_one_line_error(run_limited("info " + long_name), {long_name.substr(0, 40)});
}

// A FIFO where a file is expected: opening it blocks until something writes to it, so assess and
// calibrate glove hung forever. Each now refuses it in one line (killed after 60 s otherwise).
TEST(HostileInput, AFifoForAFileIsRefusedNotWaitedOn) {
  const fs::path fifo = hapsim::test::temp_path("input.fifo");
  fs::remove(fifo);
  ASSERT_EQ(::mkfifo(fifo.c_str(), 0600), 0);
  expect_one_line_error(run_limited("assess " + fifo.string()),
                        {fifo.string(), "not a regular file"});
  const std::string example = std::string(HAPSIM_SOURCE_DIR) + "/examples/glove_calibration/";
  expect_one_line_error(
      run_limited("calibrate glove " + fifo.string() + " --procedure " + example +
                  "procedure.json --out " + hapsim::test::temp_path("user.json").string()),
      {fifo.string(), "pipe"});
  expect_one_line_error(
      run_limited("run " + kScenes + "knee_paper.json --device sim:" + fifo.string()),
      {fifo.string()});
  fs::remove(fifo);
}

TEST(HostileInput, UnboundedStepCountsAreRefused) {
  const fs::path tiny_dt = knee_with("tiny_dt.json", "\"dt_s\": 0.001", "\"dt_s\": 1e-9");
  expect_one_line_error(run_limited("run " + tiny_dt.string()), {tiny_dt.string(), "steps"});
  const std::string knee = kScenes + "knee_procedural.json";
  expect_one_line_error(run_limited("run " + knee + " --duration 1e300"), {"--duration"});
  expect_one_line_error(run_limited("run " + knee + " --duration nan"), {"--duration", "nan"});
  const fs::path long_traj =
      write("long.csv", "t,x,y,z,qw,qx,qy,qz\n0,0,0,0.2,1,0,0,0\n1e300,0,0,0.2,1,0,0,0\n");
  expect_one_line_error(run_limited("run " + knee + " --device sim:" + long_traj.string()),
                        {knee, "steps", "at most"});
}

TEST(HostileInput, DevZeroAsTrajectoryIsRefusedAtOnce) {
  expect_one_line_error(run_limited("run " + kScenes + "knee_paper.json --device sim:/dev/zero"),
                        {"/dev/zero", "not a text file"});
}

TEST(HostileInput, WritingToAFullDiskFails) {
  // The GP7's URDF as the fuzz corpus ships it (BSD-3-Clause, attributed in the file): a real
  // chain that needs no ../shared.
  const std::string gp7 = std::string(HAPSIM_SOURCE_DIR) + "/fuzz/corpus/urdf/gp7.urdf";
  const fs::path joints = write("gp7_joints.csv", "0,0,0,0,0,0\n");
  if (fs::exists("/dev/full")) {
    expect_one_line_error(run_limited("info builtin:box --json /dev/full"), {"/dev/full"});
    const fs::path points = write("points_full.csv", "0,0,0\n");
    expect_one_line_error(
        run_limited("query builtin:box --points " + points.string() + " --out /dev/full"),
        {"--out /dev/full", "write failed"});
    expect_one_line_error(
        run_limited("query builtin:box --points " + points.string() + " --json /dev/full"),
        {"--json /dev/full", "write failed"});
    expect_one_line_error(
        run_limited("fk " + gp7 + " --joints " + joints.string() + " --out /dev/full"),
        {"--out /dev/full", "write failed"});
  }
}

TEST(HostileInput, QueryPointTooFarIsRefused) {
  const fs::path points = write("far_points.csv", "0,0,0\n1e155,0,0\n");
  expect_one_line_error(run_limited("query builtin:box --points " + points.string()),
                        {points.string(), "point 2", "1e+155 m from the origin"});
}

}  // namespace
