// `hapsim info` on a tet mesh as a user runs it: a Gmsh file written here (two 10 mm cubes, each
// its own region, in millimetres) is described with counts, regions, volume and the quality of
// the cube's six path tetrahedra known by hand; an inverted element ends the command with one
// line naming the file, the line and the element, exit status 2.
#include <nlohmann/json.hpp>

#include "hapsim_process.h"

#include "hapsim/geometry/tet_mesh.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

namespace {

using hapsim::test::run_hapsim;
using hapsim::test::RunResult;

// Gmsh 4.1 ASCII of `mesh` with one volume entity per region (physical tag = region); the line
// each tet is written on goes to `line_of_tet`.
std::string gmsh_text(const hapsim::TetMesh& mesh, std::vector<std::size_t>* line_of_tet) {
  std::vector<std::int32_t> regions(mesh.regions);
  std::sort(regions.begin(), regions.end());
  regions.erase(std::unique(regions.begin(), regions.end()), regions.end());
  std::ostringstream s;
  std::size_t line = 0;
  const auto put = [&](const std::string& text) {
    s << text << "\n";
    ++line;
  };
  put("$MeshFormat\n4.1 0 8\n$EndMeshFormat");
  line += 2;
  put("$Entities");
  put("0 0 0 " + std::to_string(regions.size()));
  for (std::size_t e = 0; e < regions.size(); ++e) {
    put(std::to_string(e + 1) + " 0 0 0 1 1 1 1 " + std::to_string(regions[e]) + " 0");
  }
  put("$EndEntities");
  put("$Nodes");
  const std::string n = std::to_string(mesh.node_count());
  put("1 " + n + " 1 " + n);
  put("3 1 0 " + n);
  for (std::size_t i = 0; i < mesh.node_count(); ++i) {
    put(std::to_string(i + 1));
  }
  for (const hapsim::Vec3& p : mesh.nodes) {
    std::ostringstream xyz;
    xyz.precision(17);
    xyz << p.x() << " " << p.y() << " " << p.z();
    put(xyz.str());
  }
  put("$EndNodes");
  put("$Elements");
  put(std::to_string(regions.size()) + " " + std::to_string(mesh.tet_count()) + " 1 " +
      std::to_string(mesh.tet_count()));
  line_of_tet->assign(mesh.tet_count(), 0);
  std::size_t tag = 1;
  for (std::size_t e = 0; e < regions.size(); ++e) {
    const auto count = std::count(mesh.regions.begin(), mesh.regions.end(), regions[e]);
    put("3 " + std::to_string(e + 1) + " 4 " + std::to_string(count));
    for (std::size_t t = 0; t < mesh.tet_count(); ++t) {
      if (mesh.regions[t] == regions[e]) {
        const hapsim::TetIndices& k = mesh.tets[t];
        put(std::to_string(tag++) + " " + std::to_string(k[0] + 1) + " " +
            std::to_string(k[1] + 1) + " " + std::to_string(k[2] + 1) + " " +
            std::to_string(k[3] + 1));
        (*line_of_tet)[t] = line;
      }
    }
  }
  put("$EndElements");
  return s.str();
}

// Two 10 mm cubes side by side, in millimetres: region 1 is the cube at x < 10, region 2 the other.
hapsim::TetMesh two_cubes_mm() {
  hapsim::TetMesh m = hapsim::make_tet_block(hapsim::Vec3(20, 10, 10), {2, 1, 1});
  for (std::size_t t = 0; t < m.tet_count(); ++t) {
    m.regions.push_back(m.nodes[m.tets[t][0]].x() < 10 ? 1 : 2);
  }
  return m;
}

TEST(InfoTetMesh, DescribesCountsRegionsVolumeAndQuality) {
  std::vector<std::size_t> lines;
  const auto msh = hapsim::test::write_file("two_cubes_mm.msh", gmsh_text(two_cubes_mm(), &lines));
  const auto json_path = hapsim::test::temp_path("two_cubes_mm.json");
  const RunResult r =
      run_hapsim("info " + msh.string() + " --scale 0.001 --json " + json_path.string());
  ASSERT_EQ(r.exit_code, 0) << r.output;
  // 3·2·2 grid nodes, 6 tets per cube, 2 triangles per cube face on the outside (10 faces).
  EXPECT_NE(r.output.find("12 nodes, 12 tetrahedra, 20 boundary triangles"), std::string::npos)
      << r.output;
  EXPECT_NE(r.output.find("regions      2 (1: 6 tets, 2: 6 tets)"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("volume       2000 mm^3"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("dihedral 45.00 to 90.00 deg"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("0 inverted, 0 degenerate, 1 piece"), std::string::npos) << r.output;

  std::ifstream in(json_path);
  const nlohmann::json j = nlohmann::json::parse(in);
  EXPECT_EQ(j.at("nodes").get<std::size_t>(), 12u);
  EXPECT_EQ(j.at("tets").get<std::size_t>(), 12u);
  EXPECT_EQ(j.at("boundary_triangles").get<std::size_t>(), 20u);
  ASSERT_EQ(j.at("regions").size(), 2u);
  EXPECT_EQ(j.at("regions")[1].at("region").get<int>(), 2);
  EXPECT_EQ(j.at("regions")[1].at("tets").get<std::size_t>(), 6u);
  EXPECT_NEAR(j.at("volume_m3").get<double>(), 2e-6, 1e-18);
  EXPECT_NEAR(j.at("bounds_m").at("max")[0].get<double>(), 0.02, 1e-15);
  // A cube's path tetrahedron (orthoscheme): dihedral angles of 45°, 60° and 90°; inradius
  // 3V/A = ½/(1 + √2) of the cube's side, longest edge √3 sides.
  const auto& q = j.at("quality");
  EXPECT_NEAR(q.at("min_dihedral_deg").get<double>(), 45.0, 1e-9);
  EXPECT_NEAR(q.at("max_dihedral_deg").get<double>(), 90.0, 1e-9);
  const double inradius = 0.5 / (1.0 + std::sqrt(2.0));
  EXPECT_NEAR(q.at("max_aspect_ratio").get<double>(),
              std::sqrt(3.0) / (2.0 * std::sqrt(6.0) * inradius), 1e-9);
  EXPECT_EQ(q.at("inverted").get<int>(), 0);
  EXPECT_EQ(q.at("pieces").get<int>(), 1);
}

TEST(InfoTetMesh, AnInvertedElementExitsTwoNamingFileLineAndElement) {
  hapsim::TetMesh m = two_cubes_mm();
  std::swap(m.tets[7][0], m.tets[7][1]);  // one tet turned inside out, the rest as they were
  std::vector<std::size_t> lines;
  const auto msh = hapsim::test::write_file("inverted_mm.msh", gmsh_text(m, &lines));
  const RunResult r = run_hapsim("info " + msh.string());
  EXPECT_EQ(r.exit_code, 2) << r.output;
  // Its cube's six tets share the 1000 mm³ equally.
  const std::string expected = msh.string() + ":" + std::to_string(lines[7]) +
                               ": element 7: inverted (signed volume -167 file units^3)";
  EXPECT_NE(r.output.find(expected), std::string::npos) << r.output;
  EXPECT_EQ(std::count(r.output.begin(), r.output.end(), '\n'), 1) << r.output;
}

TEST(InfoTetMesh, ABadFileExitsTwoWithOneLine) {
  const auto msh = hapsim::test::write_file(
      "v2.msh", "$MeshFormat\n2.2 0 8\n$EndMeshFormat\n$Nodes\n0\n$EndNodes\n");
  const RunResult r = run_hapsim("info " + msh.string());
  EXPECT_EQ(r.exit_code, 2) << r.output;
  EXPECT_NE(r.output.find(msh.string() + ":2: MSH version 2.2 is not supported"), std::string::npos)
      << r.output;
  EXPECT_EQ(std::count(r.output.begin(), r.output.end(), '\n'), 1) << r.output;
}

}  // namespace
