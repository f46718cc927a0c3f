// `hapsim assess` as a user runs it, on a session recorded by `hapsim run --record`: the JSON of
// the contract (docs/assessment.md) is written and says what the session did (a press of a sphere
// whose force k·depth is analytic); the report folder gets its three files and the report page; a
// missing scene, a scene without an assessment, a recording of another scene and a bad definition
// are each one line with exit status 2.
#include "hapsim/device/recording.h"

#include <nlohmann/json.hpp>

#include "hapsim_process.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>

namespace {

namespace fs = std::filesystem;
using hapsim::test::run_hapsim;
using hapsim::test::RunResult;
using hapsim::test::temp_path;
using hapsim::test::write_file;

// A probe pressing a 50 mm sphere (300 N/m, no damping) 30 mm deep and back over 8 s: over the
// 3.0015 N limit for t in (2.0005, 5.9995) s (recording_assessment_test.cpp works it out).
std::string press_scene(const std::string& trajectory) {
  return R"({
    "format": "hapsim-scene/1",
    "world": { "passivity_damping_factor": 0 },
    "materials": { "gel": { "response": "penalty", "stiffness_n_per_m": 300,
                            "max_penetration_m": 0.05, "max_force_n": 100 } },
    "bodies": [ { "name": "ball", "geometry": { "sphere": { "radius_m": 0.05 } },
                  "materials": "gel" } ],
    "tools": [ { "name": "tip", "radius_m": 0.005 } ],
    "device": { "profile": "omega3", "trajectory": ")" +
         trajectory + R"(" },
    "run": { "duration_s": 8.0 },
    "assessment": {
      "landmarks": [ { "name": "top", "segment": "ball", "point_m": [0, 0, 0.05],
                       "radius_m": 0.002, "force_n": 1.0, "dwell_s": 0.5 },
                     { "name": "side", "segment": "ball", "point_m": [0.05, 0, 0],
                       "radius_m": 0.005, "force_n": 1.0 } ],
      "limits": [ { "segment": "ball", "max_force_n": 3.0015 } ]
    }
  })";
}

struct Recorded {
  fs::path scene;
  fs::path recording;
};

Recorded record_press(const std::string& name) {
  const fs::path csv = write_file(name + ".csv",
                                  "t,x,y,z,qw,qx,qy,qz\n0,0,0,0.065,1,0,0,0\n4,0,0,0.025,1,0,0,0\n"
                                  "8,0,0,0.065,1,0,0,0\n");
  Recorded r{write_file(name + ".json", press_scene(csv.string())), temp_path(name + ".rec")};
  const RunResult run =
      run_hapsim("run " + r.scene.string() + " -q --record " + r.recording.string());
  EXPECT_EQ(run.exit_code, 0) << run.output;
  return r;
}

bool one_line(const std::string& text) {
  return std::count(text.begin(), text.end(), '\n') == 1;
}

TEST(AssessCommand, WritesTheJsonOfWhatTheSessionDid) {
  const Recorded rec = record_press("assess_press");
  const fs::path json_path = temp_path("assess_press_result.json");
  const RunResult r =
      run_hapsim("assess " + rec.recording.string() + " --json " + json_path.string());
  ASSERT_EQ(r.exit_code, 0) << r.output;
  // The human summary: found and missed landmarks, the breach, the score.
  EXPECT_NE(r.output.find("1 of 2 found: top"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("missed       side"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("breaches     ball: 1 over 3.0 N for 3.999 s"), std::string::npos)
      << r.output;
  EXPECT_NE(r.output.find("score "), std::string::npos) << r.output;
  std::ifstream in(json_path);
  const nlohmann::json j = nlohmann::json::parse(in);
  EXPECT_EQ(j.at("schema"), "hapsim.assessment/1");
  EXPECT_EQ(j.at("recording"), rec.recording.string());
  EXPECT_EQ(j.at("scene"), rec.scene.string());  // found through the recording's header
  EXPECT_EQ(j.at("kind"), "palpation");
  EXPECT_NEAR(j.at("duration_s").get<double>(), 8.0, 1e-9);
  EXPECT_TRUE(j.at("time_limit_s").is_null());
  // The path: down 40 mm and back up, less the 10 µm of travel before the first cycle's sample.
  EXPECT_NEAR(j.at("path_length_m").get<double>(), 0.08, 2e-5);
  EXPECT_NEAR(j.at("peak_force_n").get<double>(), 9.0, 0.0031);
  ASSERT_EQ(j.at("landmarks").size(), 2u);
  EXPECT_TRUE(j.at("landmarks")[0].at("found").get<bool>());
  EXPECT_FALSE(j.at("landmarks")[1].at("found").get<bool>());
  EXPECT_TRUE(j.at("landmarks")[1].at("found_at_s").is_null());
  ASSERT_EQ(j.at("breaches").size(), 1u);
  EXPECT_NEAR(j.at("breaches")[0].at("duration_s").get<double>(), 3.999, 1e-9);
  EXPECT_EQ(j.at("limits")[0].at("breaches").get<int>(), 1);
  const auto& terms = j.at("score").at("terms");
  EXPECT_NEAR(terms.at("landmarks").get<double>(), 50.0, 1e-9);
  EXPECT_LT(terms.at("breaches").get<double>(), -5.0);
  EXPECT_FALSE(j.at("score").at("formula").get<std::string>().empty());
  EXPECT_TRUE(j.at("picture").is_null());  // no --report
}

TEST(AssessCommand, AReportFolderGetsTheJsonTheForcesAndThePicture) {
  const Recorded rec = record_press("assess_report");
  const fs::path dir = temp_path("assess_report_out");
  fs::remove_all(dir);
  const RunResult r = run_hapsim("assess " + rec.recording.string() + " --report " + dir.string());
  ASSERT_EQ(r.exit_code, 0) << r.output;
  ASSERT_TRUE(fs::is_regular_file(dir / "assessment.json"));
  // The report script's page (python/hapsim/assessment_report.py), naming the tissue.
  ASSERT_TRUE(fs::is_regular_file(dir / "index.html"));
  {
    std::ifstream page_in(dir / "index.html");
    const std::string page((std::istreambuf_iterator<char>(page_in)),
                           std::istreambuf_iterator<char>());
    EXPECT_NE(page.find("ball"), std::string::npos);
    EXPECT_NE(page.find("data:image/png;base64,"), std::string::npos);
  }
  std::ifstream in(dir / "assessment.json");
  const nlohmann::json j = nlohmann::json::parse(in);
  EXPECT_EQ(j.at("forces").at("file"), "forces.csv");
  EXPECT_EQ(j.at("forces").at("columns"), nlohmann::json::array({"t_s", "total_force_n", "ball"}));
  const auto rows = hapsim::test::read_csv_numbers(dir / "forces.csv");
  ASSERT_EQ(rows.size(), 800u);  // 8 s in 10 ms bins
  double peak = 0.0;
  for (const auto& row : rows) {
    ASSERT_EQ(row.size(), 3u);
    peak = std::max(peak, row[2]);
  }
  EXPECT_NEAR(peak, 9.0, 0.0031);  // the bins keep the peak
  if (!j.at("picture").is_null()) {
    EXPECT_TRUE(fs::is_regular_file(dir / "picture.png"));
  }
}

TEST(AssessCommand, ASeriesGetsOneReportFolderPerSession) {
  const Recorded one = record_press("assess_series_1");
  const Recorded two = record_press("assess_series_2");
  const fs::path dir = temp_path("assess_series_out");
  fs::remove_all(dir);
  const RunResult r = run_hapsim("assess " + one.recording.string() + " " + two.recording.string() +
                                 " --summary --report " + dir.string());
  ASSERT_EQ(r.exit_code, 0) << r.output;
  for (const char* session : {"session-01", "session-02"}) {
    ASSERT_TRUE(fs::is_regular_file(dir / session / "assessment.json")) << session;
    std::ifstream in(dir / session / "assessment.json");
    EXPECT_EQ(nlohmann::json::parse(in).at("breaches").size(), 1u) << session;
    EXPECT_TRUE(fs::is_regular_file(dir / session / "index.html")) << session;
  }
  EXPECT_TRUE(fs::is_regular_file(dir / "index.html"));
  EXPECT_TRUE(fs::is_regular_file(dir / "learning_curve.png"));
}

TEST(AssessCommand, BadInputIsOneLineAndExitTwo) {
  const Recorded rec = record_press("assess_bad");
  {  // Another scene: a smaller sphere, so the content hash differs.
    std::string text = press_scene(temp_path("assess_bad.csv").string());
    text.replace(text.find("\"radius_m\": 0.05"), 16, "\"radius_m\": 0.04");
    const fs::path other = write_file("assess_other.json", text);
    const RunResult r =
        run_hapsim("assess " + rec.recording.string() + " --scene " + other.string());
    EXPECT_EQ(r.exit_code, 2) << r.output;
    EXPECT_TRUE(one_line(r.output)) << r.output;
    EXPECT_NE(r.output.find(rec.recording.string()), std::string::npos) << r.output;
  }
  {  // A scene without an assessment.
    std::string text = press_scene(temp_path("assess_bad.csv").string());
    text = text.substr(0, text.find(",\n    \"assessment\"")) + "\n}";
    const fs::path none = write_file("assess_none.json", text);
    const RunResult r =
        run_hapsim("assess " + rec.recording.string() + " --scene " + none.string());
    EXPECT_EQ(r.exit_code, 2) << r.output;
    EXPECT_TRUE(one_line(r.output)) << r.output;
    EXPECT_NE(r.output.find("no \"assessment\""), std::string::npos) << r.output;
  }
  {  // A bad definition: file and JSON pointer.
    std::string text = press_scene(temp_path("assess_bad.csv").string());
    text.replace(text.find("\"segment\": \"ball\", \"max_force_n\""), 17, "\"segment\": \"cube\"");
    const fs::path bad = write_file("assess_badlimit.json", text);
    const RunResult r = run_hapsim("assess " + rec.recording.string() + " --scene " + bad.string());
    EXPECT_EQ(r.exit_code, 2) << r.output;
    EXPECT_TRUE(one_line(r.output)) << r.output;
    EXPECT_NE(r.output.find(bad.string() + ":/assessment/limits/0/segment"), std::string::npos)
        << r.output;
  }
  {  // The scene moved away: the recording names it, but it is not there.
    const Recorded moved = record_press("assess_moved");
    fs::rename(moved.scene, temp_path("assess_moved_elsewhere.json"));
    const RunResult r = run_hapsim("assess " + moved.recording.string());
    EXPECT_EQ(r.exit_code, 2) << r.output;
    EXPECT_TRUE(one_line(r.output)) << r.output;
    EXPECT_NE(r.output.find("give --scene FILE"), std::string::npos) << r.output;
  }
  {  // Not a recording.
    const fs::path junk = write_file("assess_junk.rec", "not a recording");
    const RunResult r = run_hapsim("assess " + junk.string());
    EXPECT_EQ(r.exit_code, 2) << r.output;
    EXPECT_TRUE(one_line(r.output)) << r.output;
  }
  {  // Several recordings without --summary.
    const RunResult r =
        run_hapsim("assess " + rec.recording.string() + " " + rec.recording.string());
    EXPECT_EQ(r.exit_code, 2) << r.output;
    EXPECT_NE(r.output.find("--summary"), std::string::npos) << r.output;
  }
}

// A recording's header is data anyone can write: the scene it names is followed only to a .json
// file below the recording's folder or a scenes/ folder. A header naming /etc/passwd, or a real
// scene elsewhere, is refused with one line (nothing of the file echoed), and the header's text is
// printed with control characters escaped (no terminal escape sequence reaches the screen).
TEST(AssessCommand, AHeaderIsNotAPathToFollow) {
  // A recording whose header names `scene_path` (its frames never matter: it is refused first).
  const auto crafted = [](const std::string& name, const std::string& scene_path) {
    const fs::path rec = temp_path(name);
    hapsim::SessionRecorder recorder(rec, "crafted", 4,
                                     hapsim::SessionRecorder::Overflow::kFlushInline, scene_path);
    EXPECT_TRUE(recorder.record(hapsim::RecordedFrame{}));
    recorder.close();
    return rec;
  };
  {
    const fs::path rec = crafted("assess_passwd.rec", "/etc/passwd");
    const RunResult r = run_hapsim("assess " + rec.string());
    EXPECT_EQ(r.exit_code, 2) << r.output;
    EXPECT_TRUE(one_line(r.output)) << r.output;
    EXPECT_NE(r.output.find("'/etc/passwd'"), std::string::npos) << r.output;
    EXPECT_NE(r.output.find("not opened (give --scene FILE"), std::string::npos) << r.output;
    EXPECT_EQ(r.output.find("root:"), std::string::npos) << r.output;  // nothing of it read
  }
  {  // A real scene, but in a folder above the recording's: refused too.
    const Recorded real = record_press("assess_elsewhere");
    const fs::path below = temp_path("assess_below");
    fs::create_directories(below);
    const fs::path moved = below / "session.rec";
    fs::copy_file(real.recording, moved, fs::copy_options::overwrite_existing);
    const RunResult r = run_hapsim("assess " + moved.string());
    EXPECT_EQ(r.exit_code, 2) << r.output;
    EXPECT_TRUE(one_line(r.output)) << r.output;
    EXPECT_NE(r.output.find("not opened"), std::string::npos) << r.output;
    // Given on the command line it is the user's choice, and assessed.
    const RunResult given =
        run_hapsim("assess " + moved.string() + " --scene " + real.scene.string());
    EXPECT_EQ(given.exit_code, 0) << given.output;
  }
  {  // Escape codes in the header's path are printed escaped.
    const fs::path rec = crafted("assess_escape.rec", "/nowhere/\x1b]0;owned\x07\x1b[2J.json");
    const RunResult r = run_hapsim("assess " + rec.string());
    EXPECT_EQ(r.exit_code, 2) << r.output;
    EXPECT_TRUE(one_line(r.output)) << r.output;
    EXPECT_EQ(r.output.find('\x1b'), std::string::npos) << r.output;
    EXPECT_EQ(r.output.find('\x07'), std::string::npos) << r.output;
    EXPECT_NE(r.output.find("/nowhere/\\x1b]0;owned\\x07\\x1b[2J.json"), std::string::npos)
        << r.output;
  }
}

}  // namespace
