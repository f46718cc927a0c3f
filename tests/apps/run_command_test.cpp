// `hapsim run` as a user runs it: the shipped knee scene palpates without pop-through or a force
// above the device's rating, writes the JSON the issue asks for, replays its own recording bit
// for bit, and every bad input is one named line with exit status 2.
#include <nlohmann/json.hpp>

#include "hapsim_process.h"

#include "hapsim/core/data_dir.h"
#include "hapsim/core/device_profile.h"
#include "hapsim/geometry/mesh_io.h"
#include "hapsim/geometry/procedural.h"
#include "support/test_data.h"

#include <gtest/gtest.h>

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <map>
#include <optional>
#include <string>
#include <utility>

namespace {

using hapsim::test::run_hapsim;
using hapsim::test::RunResult;
using hapsim::test::temp_path;
using hapsim::test::write_file;

const std::string kKnee = std::string(HAPSIM_SCENES_DIR) + "/knee_procedural.json";

TEST(RunCommand, KneePalpationReportsAndWritesJson) {
  const auto json_path = temp_path("knee_procedural.json");
  const RunResult r = run_hapsim("run " + kKnee + " --duration 4 -q --json " + json_path.string());
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_NE(r.output.find("pop-throughs: 0"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("step cost: p50"), std::string::npos) << r.output;
  std::ifstream in(json_path);
  const nlohmann::json j = nlohmann::json::parse(in);
  EXPECT_EQ(j.at("steps").get<std::size_t>(), 4000u);
  EXPECT_EQ(j.at("pop_throughs").get<std::size_t>(), 0u);
  EXPECT_EQ(j.at("max_force_limit_violations").get<std::size_t>(), 0u);
  const auto& us = j.at("step_us");
  EXPECT_GT(us.at("p50").get<double>(), 0.0);
  EXPECT_LE(us.at("p50").get<double>(), us.at("p99").get<double>());
  EXPECT_LE(us.at("p99").get<double>(), us.at("max").get<double>());
  ASSERT_GE(j.at("tools").size(), 1u);
  const auto& tool = j.at("tools")[0];
  // The palpation presses tissue in its first seconds: the tool felt something, and never more
  // than the device may render.
  EXPECT_GT(tool.at("peak_force_n").get<double>(), 0.1);
  EXPECT_LE(tool.at("peak_force_n").get<double>(), j.at("peak_command_force_n").get<double>());
  EXPECT_GE(tool.at("mean_force_n").get<double>(), 0.0);
  std::size_t contacts = 0;
  double deflection = 0.0;
  for (const auto& s : j.at("segments")) {
    ASSERT_TRUE(s.contains("name"));
    contacts += s.at("contacts").get<std::size_t>();
    deflection = std::max(deflection, s.at("max_deflection_m").get<double>());
  }
  EXPECT_GT(contacts, 100u);
  EXPECT_GT(deflection, 0.0);
  EXPECT_LT(deflection, 0.02);
}

// The hand variant: two fingers press at once, the index on the patella and the middle finger on
// the patellar tendon, each feeling its own segment through its own glove actuator.
TEST(RunCommand, KneeHandPressesTwoSegmentsWithTwoFingers) {
  const auto json_path = temp_path("knee_hand_procedural.json");
  const RunResult r = run_hapsim("run " + std::string(HAPSIM_SCENES_DIR) +
                                 "/knee_hand_procedural.json -q --json " + json_path.string());
  ASSERT_EQ(r.exit_code, 0) << r.output;
  std::ifstream in(json_path);
  const nlohmann::json j = nlohmann::json::parse(in);
  std::map<std::string, double> tool_peak;
  for (const auto& t : j.at("tools")) {
    tool_peak[t.at("name").get<std::string>()] = t.at("peak_force_n").get<double>();
  }
  EXPECT_GT(tool_peak.at("index"), 0.5);
  EXPECT_GT(tool_peak.at("middle"), 0.5);
  EXPECT_EQ(tool_peak.at("thumb"), 0.0);  // curled out of the way
  EXPECT_EQ(tool_peak.at("ring"), 0.0);
  std::map<std::string, std::size_t> contacts;
  for (const auto& s : j.at("segments")) {
    contacts[s.at("name").get<std::string>()] = s.at("contacts").get<std::size_t>();
  }
  EXPECT_GT(contacts["patella"], 100u);
  EXPECT_GT(contacts["patellar_tendon"], 100u);
  EXPECT_EQ(j.at("pop_throughs").get<std::size_t>(), 0u);
  EXPECT_EQ(j.at("max_force_limit_violations").get<std::size_t>(), 0u);
}

// The simulated glove plays a recorded file: tracker pose plus j0..j14 (three angles per finger).
// The hand hovers in front of the knee, fingers across it, and only the index curls in (its MCP
// from 0 to 1.5 rad over 1 s): only the index tool may touch.
TEST(RunCommand, GlovePlaysARecordedFile) {
  std::string csv = "t,x,y,z,qw,qx,qy,qz";
  for (int j = 0; j < 15; ++j) {
    csv += ",j" + std::to_string(j);
  }
  csv += "\n";
  for (int k = 0; k <= 10; ++k) {
    const double t = 0.1 * k;
    // Back of the hand towards +y (hand z = +y, a −90° turn about x), fingers along +x.
    csv += std::to_string(t) + ",-0.08,0.10,0.02,0.7071067811865476,-0.7071067811865476,0,0";
    for (int j = 0; j < 15; ++j) {
      const bool index_mcp = j == 4;
      // Appended in two steps: `"," + std::to_string(…)` trips GCC 12's -Wrestrict false
      // positive at -O3 (GCC bug 105651) inside libstdc++'s operator+.
      csv += ',';
      csv += std::to_string(index_mcp ? 0.15 * k : 0.0);
    }
    csv += "\n";
  }
  const auto traj = write_file("glove.csv", csv);
  const auto json_path = temp_path("glove_run.json");
  const RunResult r =
      run_hapsim("run " + std::string(HAPSIM_SCENES_DIR) + "/knee_hand_procedural.json -q " +
                 "--device sim:" + traj.string() + " --json " + json_path.string());
  ASSERT_EQ(r.exit_code, 0) << r.output;
  std::ifstream in(json_path);
  const nlohmann::json j = nlohmann::json::parse(in);
  EXPECT_EQ(j.at("steps").get<std::size_t>(), 1000u);
  EXPECT_EQ(j.at("pop_throughs").get<std::size_t>(), 0u);
  std::map<std::string, double> tool_peak;
  for (const auto& t : j.at("tools")) {
    tool_peak[t.at("name").get<std::string>()] = t.at("peak_force_n").get<double>();
  }
  EXPECT_GT(tool_peak.at("index"), 0.5);
  EXPECT_EQ(tool_peak.at("thumb"), 0.0);
  EXPECT_EQ(tool_peak.at("middle"), 0.0);
  EXPECT_EQ(tool_peak.at("ring"), 0.0);
}

// The CSG example: a block minus a hole minus a dimple, its contacts from the solid's signed
// distance. Pressing a flat face 2 mm with k = 1500 N/m is k·x = 3 N; the dimple (concave, the
// proxy settles on its slope) a little more; never through, never at the 6 N cap, and the run
// replays bit for bit.
TEST(RunCommand, CsgBlockPressesItsFacesAndReplays) {
  const std::string scene = std::string(HAPSIM_SCENES_DIR) + "/csg_block.json";
  const auto json_path = temp_path("csg_block.json");
  const auto rec = temp_path("csg_block.rec");
  const RunResult r =
      run_hapsim("run " + scene + " -q --json " + json_path.string() + " --record " + rec.string());
  ASSERT_EQ(r.exit_code, 0) << r.output;
  std::ifstream in(json_path);
  const nlohmann::json j = nlohmann::json::parse(in);
  const double peak = j.at("tools").at(0).at("peak_force_n").get<double>();
  EXPECT_GT(peak, 1500.0 * 0.002 - 0.05);
  EXPECT_LT(peak, 4.0);
  EXPECT_GT(j.at("segments").at(0).at("contacts").get<std::size_t>(), 2000u);
  EXPECT_EQ(j.at("pop_throughs").get<std::size_t>(), 0u);
  EXPECT_EQ(j.at("max_force_limit_violations").get<std::size_t>(), 0u);
  const RunResult replay = run_hapsim("run " + scene + " -q --replay " + rec.string());
  EXPECT_EQ(replay.exit_code, 0) << replay.output;
}

TEST(RunCommand, RecordingReplaysBitForBit) {
  const auto rec = temp_path("knee.rec");
  const RunResult a = run_hapsim("run " + kKnee + " --duration 2 -q --record " + rec.string());
  ASSERT_EQ(a.exit_code, 0) << a.output;
  EXPECT_NE(a.output.find("2000 frames"), std::string::npos) << a.output;
  const RunResult b = run_hapsim("run " + kKnee + " -q --replay " + rec.string());
  EXPECT_EQ(b.exit_code, 0) << b.output;
  EXPECT_NE(b.output.find("identical"), std::string::npos) << b.output;
  // The approximate knee method changes the forces: the replay check must notice.
  const RunResult c = run_hapsim("run " + kKnee + " -q --method knee --replay " + rec.string());
  if (c.output.find("different scene") == std::string::npos) {
    EXPECT_EQ(c.exit_code, 1) << c.output;
    EXPECT_NE(c.output.find("DIFFERS"), std::string::npos) << c.output;
  } else {
    EXPECT_EQ(c.exit_code, 2) << c.output;  // the method is part of the scene's hash
  }
}

TEST(RunCommand, PlaysATrajectoryFile) {
  // 1 s hovering far above everything, then the end: no contact, zero force.
  const auto traj =
      write_file("hover.csv", "t,x,y,z,qw,qx,qy,qz\n0,0,0,1,1,0,0,0\n1,0,0,1.01,1,0,0,0\n");
  const auto json_path = temp_path("hover.json");
  const RunResult r = run_hapsim("run " + kKnee + " -q --device sim:" + traj.string() + " --json " +
                                 json_path.string());
  ASSERT_EQ(r.exit_code, 0) << r.output;
  std::ifstream in(json_path);
  const nlohmann::json j = nlohmann::json::parse(in);
  EXPECT_EQ(j.at("steps").get<std::size_t>(), 1000u);
  EXPECT_EQ(j.at("peak_command_force_n").get<double>(), 0.0);
  // ... which the run says before it starts.
  ASSERT_EQ(j.at("warnings").size(), 1u);
  EXPECT_EQ(j["warnings"][0].get<std::string>().rfind(
                traj.string() + ": the trajectory never comes within reach of a body", 0),
            0u)
      << j["warnings"];
}

std::size_t count(const std::string& text, const std::string& part) {
  std::size_t n = 0;
  for (std::size_t at = text.find(part); at != std::string::npos; at = text.find(part, at + 1)) {
    ++n;
  }
  return n;
}

// What was silently changed is said (docs/scene-format.md, "Warnings"): a mesh in millimetres
// read as metres and a trajectory far from everything each warn once, through the log, before the
// run, and the JSON lists the same lines.
TEST(RunCommand, AMisScaledMeshAndAFarTrajectoryWarnOnceEach) {
  const auto mesh = temp_path("patella.stl");
  hapsim::MeshSaveOptions mm;
  mm.scale = 1000.0;  // file units per metre: the numbers are millimetres
  hapsim::save_mesh(mesh, hapsim::make_box(hapsim::Vec3::Constant(0.021)), mm);
  const auto far = write_file("far.csv",
                              "t,x,y,z,qw,qx,qy,qz\n0,0,0,100,1,0,0,0\n"
                              "0.5,0,0,100,1,0,0,0\n");
  const auto scene = write_file("misscaled.json", R"({
    "format": "hapsim-scene/1",
    "materials": { "bone": { "stiffness_n_per_m": 300 } },
    "bodies": [ { "name": "patella", "geometry": { "mesh": { "file": ")" +
                                                      mesh.string() + R"(" } },
                  "materials": "bone" } ],
    "tools": [ { "name": "tip", "radius_m": 0.005 } ],
    "device": { "profile": "touch", "trajectory": ")" +
                                                      far.string() + R"(" }
  })");
  const auto json_path = temp_path("misscaled_run.json");
  const RunResult r = run_hapsim("run " + scene.string() + " -q --json " + json_path.string());
  ASSERT_EQ(r.exit_code, 0) << r.output;
  const std::string mesh_warning =
      scene.string() + ":/bodies/0/geometry/mesh: " + mesh.string() + " is 42 m across at scale 1";
  const std::string far_warning = far.string() + ": the trajectory never comes within reach";
  EXPECT_EQ(count(r.output, mesh_warning), 1u) << r.output;
  EXPECT_EQ(count(r.output, far_warning), 1u) << r.output;
  EXPECT_EQ(count(r.output, "[warning]"), 2u) << r.output;
  EXPECT_NE(r.output.find("Use \"scale\": 0.001"), std::string::npos) << r.output;
  // Before the run's figures.
  EXPECT_LT(r.output.find(far_warning), r.output.find("steps,")) << r.output;
  std::ifstream in(json_path);
  const nlohmann::json j = nlohmann::json::parse(in);
  ASSERT_EQ(j.at("warnings").size(), 2u);
  EXPECT_EQ(j["warnings"][0].get<std::string>().rfind(mesh_warning, 0), 0u) << j["warnings"];
  EXPECT_EQ(j["warnings"][1].get<std::string>().rfind(far_warning, 0), 0u) << j["warnings"];
  EXPECT_NE(r.output.find(j["warnings"][1].get<std::string>()), std::string::npos);
}

// The glove's actuators are rated 400 N/m (device_profile.h, rutgers_master): the knee_hand
// materials above that are named once in the summary and listed in the JSON, each with its own
// stiffness read from the scene file.
TEST(RunCommand, KneeHandNamesTheMaterialsClampedToTheGlovesStiffness) {
  const std::string scene_file = std::string(HAPSIM_SCENES_DIR) + "/knee_hand_procedural.json";
  const auto json_path = temp_path("knee_hand_clamps.json");
  const RunResult r =
      run_hapsim("run " + scene_file + " --duration 0.05 -q --json " + json_path.string());
  ASSERT_EQ(r.exit_code, 0) << r.output;
  const double rating = hapsim::device_profile("rutgers_master").max_stiffness_n_per_m;
  std::ifstream scene_in(scene_file);
  const nlohmann::json scene = nlohmann::json::parse(scene_in);
  std::map<std::string, double> stiffer;
  for (const auto& [name, m] : scene.at("materials").items()) {
    if (m.at("stiffness_n_per_m").get<double>() > rating) {
      stiffer[name] = m.at("stiffness_n_per_m").get<double>();
    }
  }
  ASSERT_FALSE(stiffer.empty());
  std::ifstream in(json_path);
  const nlohmann::json j = nlohmann::json::parse(in);
  std::map<std::string, double> listed;
  for (const auto& c : j.at("stiffness_clamps")) {
    listed[c.at("material").get<std::string>()] = c.at("stiffness_n_per_m").get<double>();
    EXPECT_EQ(c.at("clamped_to_n_per_m").get<double>(), rating);
  }
  EXPECT_EQ(listed, stiffer);
  EXPECT_EQ(count(r.output, "stiffness clamped to the device's rated 400 N/m: material "), 1u)
      << r.output;
  for (const auto& [name, k] : stiffer) {
    char part[128];
    std::snprintf(part, sizeof part, "'%s' %g N/m", name.c_str(), k);
    EXPECT_NE(r.output.find(part), std::string::npos) << part << "\n" << r.output;
  }
  EXPECT_TRUE(j.at("warnings").empty()) << j["warnings"];
}

// The shipped scenes run without a warning, and (but knee_hand, above) without a clamp.
void expect_runs_without_warnings(const std::string& name, const std::string& extra_args = {}) {
  SCOPED_TRACE(name);
  const std::string args =
      "run " + std::string(HAPSIM_SCENES_DIR) + "/" + name + ".json" + extra_args;
  const auto json_path = temp_path(name + "_warnings.json");
  // Whole runs (a teleoperation scene is judged on its whole pick-and-place): under 3 s each.
  const RunResult r = run_hapsim(args + " -q --json " + json_path.string());
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_EQ(r.output.find("[warning]"), std::string::npos) << r.output;
  std::ifstream in(json_path);
  const nlohmann::json j = nlohmann::json::parse(in);
  EXPECT_TRUE(j.at("warnings").empty()) << j["warnings"];
  if (name != "knee_hand_procedural") {
    EXPECT_TRUE(j.at("stiffness_clamps").empty()) << j["stiffness_clamps"];
    EXPECT_EQ(r.output.find("stiffness clamped"), std::string::npos) << r.output;
  }
}

TEST(RunCommand, ShippedScenesRunWithoutWarnings) {
  for (const char* name : {"knee", "knee_hand_procedural", "csg_block", "teleop"}) {
    expect_runs_without_warnings(name);
  }
}

// The real-data scenes: a missing data set is a skip (a failure under HAPSIM_REQUIRE_DATA=1).
TEST(RunCommand, RealDataScenesRunWithoutWarnings) {
  for (const auto& [name, data] :
       {std::pair{"teleop_gp7", "motoman_gp7"}, std::pair{"knee_vhf", "knee_vhf_left"}}) {
    const std::filesystem::path dir = hapsim::test::data_path(data);
    HAPSIM_SKIP_WITHOUT_DATA(std::filesystem::is_directory(dir),
                             "real data for " << name << " not found at " << dir);
    expect_runs_without_warnings(name, " --data " + dir.string());
  }
}

TEST(RunCommand, BadInputsAreOneNamedLineAndExitTwo) {
  struct Case {
    std::string args;
    std::string names;
  };
  const auto broken = write_file("broken.json", "{ \"format\": \"hapsim-scene/1\", ");
  const auto bad_traj = write_file("bad.csv", "t,x,y,z,qw,qx,qy,qz\n0,0,0,nan,1,0,0,0\n");
  const Case cases[] = {
      {"run /nonexistent/scene.json", "/nonexistent/scene.json"},
      {"run " + broken.string(), "broken.json"},
      {"run " + kKnee + " --device sim:/nonexistent/t.csv", "/nonexistent/t.csv"},
      {"run " + kKnee + " --device joystick", "--device"},
      {"run " + kKnee + " --device sim:" + bad_traj.string(), "bad.csv:2"},
      {"run " + kKnee + " --duration -1", "--duration"},
      {"run " + kKnee + " --method magic", "--method"},
      {"run " + kKnee + " --replay /nonexistent/r.rec", "/nonexistent/r.rec"},
      {"run " + kKnee + " --json /nonexistent/dir/out.json", "/nonexistent/dir/out.json"},
  };
  for (const Case& c : cases) {
    SCOPED_TRACE(c.args);
    const RunResult r = run_hapsim(c.args + " -q");
    EXPECT_EQ(r.exit_code, 2) << r.output;
    EXPECT_NE(r.output.find(c.names), std::string::npos) << r.output;
    EXPECT_EQ(r.output.find("internal error"), std::string::npos) << r.output;
  }
}

}  // namespace
