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

}  // namespace
