// `hapsim info` on a triangle mesh says what a new user would otherwise get wrong: an open mesh
// has no enclosed volume (it printed one, a number that depends on where the origin is), and a
// mesh tens of metres across is almost always millimetres read as metres (a 42 m patella): the
// hint names the --scale that fixes it, and a mesh given that scale gets no hint.
#include <nlohmann/json.hpp>

#include "hapsim_process.h"

#include <gtest/gtest.h>

#include <fstream>
#include <string>

namespace {

using hapsim::test::run_hapsim;
using hapsim::test::RunResult;
using hapsim::test::temp_path;
using hapsim::test::write_file;

// A unit cube's surface scaled by `size`, as ASCII STL; `open` leaves out its top two triangles.
std::string cube_stl(double size, bool open) {
  const double s = size;
  const double v[8][3] = {{0, 0, 0}, {s, 0, 0}, {s, s, 0}, {0, s, 0},
                          {0, 0, s}, {s, 0, s}, {s, s, s}, {0, s, s}};
  const int tris[12][3] = {{0, 2, 1}, {0, 3, 2}, {4, 5, 6}, {4, 6, 7}, {0, 1, 5}, {0, 5, 4},
                           {1, 2, 6}, {1, 6, 5}, {2, 3, 7}, {2, 7, 6}, {3, 0, 4}, {3, 4, 7}};
  std::string out = "solid cube\n";
  for (int t = 0; t < 12; ++t) {
    if (open && (t == 2 || t == 3)) {
      continue;  // the top
    }
    out += "facet normal 0 0 0\nouter loop\n";
    for (int k = 0; k < 3; ++k) {
      const double* p = v[tris[t][k]];
      out += "vertex " + std::to_string(p[0]) + " " + std::to_string(p[1]) + " " +
             std::to_string(p[2]) + "\n";
    }
    out += "endloop\nendfacet\n";
  }
  return out + "endsolid cube\n";
}

nlohmann::json info_json(const std::string& args, RunResult* result) {
  const auto json_path = temp_path("info_hints.json");
  *result = run_hapsim("info " + args + " --json " + json_path.string());
  std::ifstream in(json_path);
  return nlohmann::json::parse(in);
}

TEST(InfoMeshHints, AnOpenMeshHasNoVolumeAndSaysWhy) {
  const auto closed = write_file("cube_closed.stl", cube_stl(0.02, false));
  const auto open = write_file("cube_open.stl", cube_stl(0.02, true));
  RunResult r;
  const nlohmann::json c = info_json(closed.string(), &r);
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_TRUE(c.at("closed").get<bool>());
  EXPECT_NEAR(c.at("signed_volume_m3").get<double>(), 8e-6, 1e-12);  // 20 mm cube
  const nlohmann::json o = info_json(open.string(), &r);
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_FALSE(o.at("closed").get<bool>());
  EXPECT_TRUE(o.at("signed_volume_m3").is_null());
  EXPECT_NE(r.output.find("no enclosed volume: the mesh is open (4 edges with one triangle)"),
            std::string::npos)
      << r.output;
  EXPECT_EQ(r.output.find("enclosed volume 8"), std::string::npos) << r.output;
}

TEST(InfoMeshHints, AMeshTensOfMetresAcrossGetsTheScaleThatFixesIt) {
  // A 42 mm "patella" written in millimetres, read as metres: 42 m.
  const auto mm = write_file("patella_mm.stl", cube_stl(42.0, false));
  RunResult r;
  const nlohmann::json j = info_json(mm.string(), &r);
  ASSERT_EQ(r.exit_code, 0) << r.output;
  ASSERT_TRUE(j.contains("unit_hint")) << j.dump(2);
  EXPECT_NE(j.at("unit_hint").get<std::string>().find("--scale 0.001"), std::string::npos);
  EXPECT_NE(r.output.find("units        42 m across"), std::string::npos) << r.output;
  // Given the scale, it is 42 mm and needs no hint.
  const nlohmann::json scaled = info_json(mm.string() + " --scale 0.001", &r);
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_FALSE(scaled.contains("unit_hint")) << scaled.dump(2);
  EXPECT_EQ(r.output.find("units "), std::string::npos) << r.output;
}

}  // namespace
