// The `hapsim` command as a user runs it: exit codes, one-line messages naming the bad input,
// and query output checked against analytic answers on a built-in box.
#include "hapsim_process.h"
#include "support/test_data.h"

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <sstream>
#include <string>
#include <vector>

namespace {

using hapsim::test::read_csv_numbers;
using hapsim::test::run_hapsim;
using hapsim::test::RunResult;

std::filesystem::path temp_file(const std::string& name, const std::string& content) {
  return hapsim::test::write_file(name, content);
}

TEST(Cli, NoSubcommandExitsTwo) {
  const RunResult r = run_hapsim("");
  EXPECT_EQ(r.exit_code, 2) << r.output;
}

TEST(Cli, UnknownOptionExitsTwoWithOneLine) {
  const RunResult r = run_hapsim("info builtin:box --no-such-option");
  EXPECT_EQ(r.exit_code, 2) << r.output;
  EXPECT_NE(r.output.find("--no-such-option"), std::string::npos) << r.output;
}

TEST(Cli, MissingMeshFileIsNamed) {
  const RunResult r = run_hapsim("info /nonexistent/knee.stl");
  EXPECT_EQ(r.exit_code, 2) << r.output;
  EXPECT_NE(r.output.find("/nonexistent/knee.stl"), std::string::npos) << r.output;
}

TEST(Cli, UnknownBuiltinListsKnownOnes) {
  const RunResult r = run_hapsim("info builtin:teapot");
  EXPECT_EQ(r.exit_code, 2) << r.output;
  EXPECT_NE(r.output.find("builtin:box"), std::string::npos) << r.output;
}

TEST(Cli, BadPointsFileNamesFileAndLine) {
  const auto pts = temp_file("bad_points.csv", "x,y,z\n0,0,0\n1,2\n");
  const RunResult r = run_hapsim("query builtin:box --points " + pts.string());
  EXPECT_EQ(r.exit_code, 2) << r.output;
  EXPECT_NE(r.output.find(pts.string() + ":3"), std::string::npos) << r.output;
}

TEST(Cli, NonNumericAndNanPointsAreRejected) {
  const auto text = temp_file("text_points.csv", "0,0,0\n0,zero,0\n");
  RunResult r = run_hapsim("query builtin:box --points " + text.string());
  EXPECT_EQ(r.exit_code, 2) << r.output;
  EXPECT_NE(r.output.find(":2"), std::string::npos) << r.output;
  const auto nan = temp_file("nan_points.csv", "0,0,0\nnan,0,0\n");
  r = run_hapsim("query builtin:box --points " + nan.string());
  EXPECT_EQ(r.exit_code, 2) << r.output;
  EXPECT_NE(r.output.find("finite"), std::string::npos) << r.output;
}

TEST(Cli, MissingPointsFileAndBadMethodAndBadScale) {
  RunResult r = run_hapsim("query builtin:box --points /nonexistent/p.csv");
  EXPECT_EQ(r.exit_code, 2) << r.output;
  EXPECT_NE(r.output.find("/nonexistent/p.csv"), std::string::npos) << r.output;
  const auto pts = temp_file("one_point.csv", "0,0,0\n");
  r = run_hapsim("query builtin:box --method magic --points " + pts.string());
  EXPECT_EQ(r.exit_code, 2) << r.output;
  EXPECT_NE(r.output.find("--method"), std::string::npos) << r.output;
  r = run_hapsim("query builtin:box --scale -1 --points " + pts.string());
  EXPECT_EQ(r.exit_code, 2) << r.output;
}

// The built-in box is 100 x 60 x 40 mm centred at the origin: distances are known exactly.
TEST(Cli, QueryAnswersMatchTheBoxAnalytically) {
  for (const std::string method : {"exact", "spheretree"}) {
    const auto pts =
        temp_file("box_points.csv", "x,y,z\n0,0,0\n0.08,0,0\n0.06,0.04,0\n0.0,0.0,0.019\n");
    const auto out = hapsim::test::temp_path("box_out.csv");
    const RunResult r = run_hapsim("query builtin:box --method " + method + " --points " +
                                   pts.string() + " --out " + out.string());
    ASSERT_EQ(r.exit_code, 0) << r.output;
    const auto rows = read_csv_numbers(out);
    ASSERT_EQ(rows.size(), 4U);
    for (const auto& row : rows) {
      ASSERT_EQ(row.size(), 11U);
    }
    EXPECT_NEAR(rows[0][3], -0.02, 1e-12) << method;  // centre: 20 mm inside (half height)
    EXPECT_NEAR(rows[1][3], 0.03, 1e-12) << method;   // 30 mm beyond the +x face
    EXPECT_NEAR(rows[1][4], 0.05, 1e-12) << method;   // closest point on that face
    EXPECT_NEAR(rows[1][7], 1.0, 1e-12) << method;    // normal +x
    EXPECT_NEAR(rows[2][3], std::hypot(0.01, 0.01), 1e-12) << method;  // nearest the edge
    EXPECT_NEAR(rows[3][3], -0.001, 1e-12) << method;                  // 1 mm under the top face
    EXPECT_NEAR(rows[3][9], 1.0, 1e-12) << method;                     // normal +z
  }
}

// The knee method is a method like the others: it answers the query, and reports its error
// against the exact query — checked here against the difference of the two methods' own answers.
TEST(Cli, QueryKneeMethodReportsItsErrorAgainstExact) {
  const auto knee_csv = hapsim::test::temp_path("knee_out.csv");
  const auto exact_csv = hapsim::test::temp_path("exact_out.csv");
  const auto json = hapsim::test::temp_path("knee_query.json");
  const RunResult r = run_hapsim(
      "query builtin:bumpy-sphere --method knee --points "
      "builtin:probe-path --out " +
      knee_csv.string() + " --json " + json.string());
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_NE(r.output.find("error vs exact"), std::string::npos) << r.output;
  ASSERT_EQ(run_hapsim("query builtin:bumpy-sphere --method exact --points builtin:probe-path "
                       "--out " +
                       exact_csv.string())
                .exit_code,
            0);
  const auto knee = read_csv_numbers(knee_csv);
  const auto exact = read_csv_numbers(exact_csv);
  ASSERT_EQ(knee.size(), exact.size());
  double max_error = 0.0;
  double sum_error = 0.0;
  std::size_t compared = 0;
  for (std::size_t i = 0; i < knee.size(); ++i) {
    const bool knee_answered = knee[i][10] != 4294967295.0;
    if (std::abs(exact[i][3]) > 0.01 || !knee_answered) {
      continue;  // beyond the 10 mm band (either side), or not answered: not in the error
    }
    ++compared;
    max_error = std::max(max_error, std::abs(knee[i][3] - exact[i][3]));
    sum_error += std::abs(knee[i][3] - exact[i][3]);
  }
  std::ifstream in(json);
  const nlohmann::json j = nlohmann::json::parse(in);
  const nlohmann::json& e = j.at("error_vs_exact");
  EXPECT_EQ(e.at("answered").get<std::size_t>(), compared);
  EXPECT_NEAR(e.at("max_abs_error_m").get<double>(), max_error, 1e-12);
  EXPECT_NEAR(e.at("mean_abs_error_m").get<double>(), sum_error / static_cast<double>(compared),
              1e-12);
  EXPECT_GT(max_error, 0.0);  // approximate (deep inside the body it is far off: see the summary)
}

TEST(Cli, ScaleConvertsUnitsBothWays) {
  // Same box read as millimetres: points and answers stay in mesh units.
  const auto pts = temp_file("box_points_mm.csv", "80,0,0\n");
  const auto out = hapsim::test::temp_path("box_mm.csv");
  const RunResult r =
      run_hapsim("query builtin:box --scale 1 --points " + pts.string() + " --out " + out.string());
  ASSERT_EQ(r.exit_code, 0) << r.output;
  const auto rows = read_csv_numbers(out);
  ASSERT_EQ(rows.size(), 1U);
  EXPECT_NEAR(rows[0][3], 79.95, 1e-9);  // builtin box is in metres: 80 - 0.05
}

TEST(Cli, InfoWritesJson) {
  const auto json = hapsim::test::temp_path("info.json");
  const RunResult r = run_hapsim("info builtin:box --json " + json.string());
  ASSERT_EQ(r.exit_code, 0) << r.output;
  std::ifstream in(json);
  std::stringstream ss;
  ss << in.rdbuf();
  EXPECT_NE(ss.str().find("\"triangles\": 12"), std::string::npos) << ss.str();
  EXPECT_NE(r.output.find("sphere tree"), std::string::npos) << r.output;
}

}  // namespace

// A cube of side 20 mm written as an OBJ in millimetres: loading with --scale 0.001 gives its
// exact volume and the query its exact distances.
constexpr const char* kCubeObjMm =
    "v -10 -10 -10\nv 10 -10 -10\nv 10 10 -10\nv -10 10 -10\n"
    "v -10 -10 10\nv 10 -10 10\nv 10 10 10\nv -10 10 10\n"
    "f 1 3 2\nf 1 4 3\nf 5 6 7\nf 5 7 8\nf 1 2 6\nf 1 6 5\n"
    "f 2 3 7\nf 2 7 6\nf 3 4 8\nf 3 8 7\nf 4 1 5\nf 4 5 8\n";

TEST(Cli, InfoAndQueryReadMeshFilesInMillimetres) {
  const auto obj = temp_file("cube_mm.obj", kCubeObjMm);
  const auto json = temp_file("cube_info.json", "");
  const RunResult info =
      run_hapsim("info " + obj.string() + " --scale 0.001 --json " + json.string());
  ASSERT_EQ(info.exit_code, 0) << info.output;
  EXPECT_NE(info.output.find("closed"), std::string::npos) << info.output;
  std::ifstream in(json);
  const std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  EXPECT_NE(text.find("\"validation\""), std::string::npos) << text;

  const auto points = temp_file("cube_points.csv", "x,y,z\n0,0,0\n0,0,25\n");
  const auto out = hapsim::test::temp_path("cube_out.csv");
  const RunResult q = run_hapsim("query " + obj.string() + " --scale 0.001 --points " +
                                 points.string() + " --method exact --out " + out.string());
  ASSERT_EQ(q.exit_code, 0) << q.output;
  const auto rows = read_csv_numbers(out);
  ASSERT_EQ(rows.size(), 2u);
  EXPECT_NEAR(rows[0][3], -10.0, 1e-9);  // centre: 10 mm inside, answered in the input's units
  EXPECT_NEAR(rows[1][3], 15.0, 1e-9);   // 15 mm above the top face
}

TEST(Cli, MeshWithNanCoordinatesIsRefusedAndNamed) {
  std::string bad = kCubeObjMm;
  bad.replace(0, 13, "v nan -10 -10");
  const auto obj = temp_file("cube_nan.obj", bad);
  const RunResult r = run_hapsim("info " + obj.string());
  EXPECT_EQ(r.exit_code, 2) << r.output;
  EXPECT_NE(r.output.find("cube_nan.obj"), std::string::npos) << r.output;
}

// `hapsim simplify`: a sphere to 500 vertices, written, and its Hausdorff line; bad input is one
// line and exit 2.
TEST(Cli, SimplifyWritesAClosedMeshAndItsHausdorffDistance) {
  const auto out = std::filesystem::temp_directory_path() / "hapsim_simplified.stl";
  const auto json = std::filesystem::temp_directory_path() / "hapsim_simplified.json";
  const RunResult r = run_hapsim("simplify builtin:bumpy-sphere --target-vertices 500 --out " +
                                 out.string() + " --json " + json.string());
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_NE(r.output.find("hausdorff"), std::string::npos) << r.output;
  std::ifstream in(json);
  const nlohmann::json j = nlohmann::json::parse(in);
  EXPECT_LE(j["vertices"].get<int>(), 500);
  EXPECT_TRUE(j["closed"].get<bool>());
  EXPECT_GT(j["hausdorff_m"].get<double>(), 0.0);
  EXPECT_LE(j["hausdorff_m"].get<double>(), j["hausdorff_bound_m"].get<double>());

  for (const std::string& bad :
       {"simplify builtin:box --target-vertices 0 --out " + out.string(),
        std::string("simplify builtin:box --target-vertices 10 --out x.notamesh"),
        "simplify builtin:sheet16 --target-vertices 10 --out " + out.string(),
        "simplify /nonexistent/knee.stl --target-vertices 10 --out " + out.string()}) {
    const RunResult b = run_hapsim(bad);
    EXPECT_EQ(b.exit_code, 2) << bad << ": " << b.output;
    EXPECT_EQ(std::count(b.output.begin(), b.output.end(), '\n'), 1) << b.output;
  }
}

TEST(Cli, InfoOnTheRealKnee) {
  const std::filesystem::path stl =
      hapsim::test::data_path("knee_vhf_left/stl/VHF_Left_Bone_Patella_smooth.stl");
  HAPSIM_SKIP_WITHOUT_DATA(std::filesystem::exists(stl), "real knee data not found at " << stl);
  const RunResult r = run_hapsim("info " + stl.string() + " --scale 0.001");
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_NE(r.output.find("closed"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("no defects"), std::string::npos) << r.output;
}
