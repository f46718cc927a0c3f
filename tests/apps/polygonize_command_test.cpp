// `hapsim polygonize`: a union whose pieces do not touch keeps the piece enclosing the most
// volume and says how many it dropped (the derived skin must be one closed surface).
#include "hapsim_process.h"

#include "hapsim/geometry/mesh_io.h"
#include "hapsim/geometry/mesh_validation.h"

#include <gtest/gtest.h>

#include <string>

namespace {

using hapsim::test::run_hapsim;
using hapsim::test::temp_path;
using hapsim::test::write_file;

TEST(PolygonizeCommand, TwoApartSpheresKeepTheLargerAndSaySo) {
  const auto csg = write_file("two_spheres.json",
                              R"({"union": [{"sphere": {"radius_m": 0.02}},
                    {"sphere": {"radius_m": 0.01}, "pose": {"position_m": [0.06, 0, 0]}}]})");
  const auto out = temp_path("two_spheres.stl");
  const auto r =
      run_hapsim("polygonize --csg " + csg.string() + " --cell-m 0.004 --out " + out.string());
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_NE(r.output.find("dropped      1 smaller component(s)"), std::string::npos) << r.output;
  const hapsim::TriangleMesh mesh = hapsim::load_mesh(out);
  const hapsim::MeshReport report = hapsim::validate_mesh(mesh);
  EXPECT_TRUE(report.closed);
  EXPECT_EQ(report.components, 1u);
  // The kept piece is the 20 mm sphere, centred at the origin.
  EXPECT_LT(mesh.bounds().max().x(), 0.021);
  EXPECT_GT(mesh.bounds().min().x(), -0.021);
}

// A cell coarser than the shape is refused in one line: 1e308 m crashed the tree's traversal, and
// 1e20 m wrote a mesh 5e23 mm across and called it fine.
TEST(PolygonizeCommand, ACellCoarserThanTheShapeIsRefused) {
  const auto out = temp_path("coarse.stl");
  for (const char* cell : {"1e308", "1e20", "0.06"}) {
    const auto r = run_hapsim("polygonize --mesh builtin:box --cell-m " + std::string(cell) +
                              " --out " + out.string());
    EXPECT_EQ(r.exit_code, 2) << cell << ": " << r.output;
    EXPECT_NE(r.output.find("--cell-m"), std::string::npos) << r.output;
    EXPECT_NE(r.output.find("coarser than the shape"), std::string::npos) << r.output;
  }
  const auto fine = run_hapsim("polygonize --mesh builtin:box --cell-m 0.02 --out " + out.string());
  EXPECT_EQ(fine.exit_code, 0) << fine.output;
}

}  // namespace
