// `hapsim sheet-profile`: the CSV behind paper 000's Fig. 3 is the paper's formula, written out
// here independently, z(d, F) = (F/F0)(exp(−(d/ξ)²) − exp(−(d0/ξ)²)), for the curve and for every
// grid node of the scene's sheet; a scene without a sheet is one line, exit 2.
#include "hapsim_process.h"

#include <gtest/gtest.h>

#include <cmath>
#include <fstream>
#include <sstream>
#include <string>

namespace hapsim {
namespace {

double paper_depth_mm(double d_mm, double force_n) {
  const double d0_mm = 44.0;
  const double xi_mm = 40.1;
  const double f0_n_per_mm = 3.0;
  if (d_mm >= d0_mm) {
    return 0.0;
  }
  return force_n / f0_n_per_mm *
         (std::exp(-(d_mm / xi_mm) * (d_mm / xi_mm)) -
          std::exp(-(d0_mm / xi_mm) * (d0_mm / xi_mm)));
}

TEST(SheetProfileCommand, WritesThePapersGaussianForTheCurveAndEveryGridNode) {
  const auto csv = test::temp_path("profile.csv");
  const test::RunResult r = test::run_hapsim("sheet-profile " + std::string(HAPSIM_SCENES_DIR) +
                                             "/teleop.json --force 1.5,3 --out " + csv.string());
  ASSERT_EQ(r.exit_code, 0) << r.output;
  std::ifstream in(csv);
  std::string line;
  std::size_t profile_rows = 0;
  std::size_t grid_rows = 0;
  double deepest_mm = 0.0;
  while (std::getline(in, line)) {
    if (line.empty() || line[0] == '#' || line.rfind("kind", 0) == 0) {
      continue;
    }
    std::istringstream row(line);
    std::string kind, f, d, z;
    std::getline(row, kind, ',');
    std::getline(row, f, ',');
    std::getline(row, d, ',');
    std::getline(row, z, ',');
    const double force_n = std::stod(f);
    const double depth_mm = std::stod(z);
    EXPECT_NEAR(depth_mm, paper_depth_mm(std::stod(d), force_n), 1e-6) << line;
    deepest_mm = std::max(deepest_mm, depth_mm);
    (kind == "profile" ? profile_rows : grid_rows) += 1;
  }
  // 0 .. 55 mm every 0.25 mm per force; the 16×16 nodes within 55 mm of the centre per force.
  EXPECT_EQ(profile_rows, 2u * 221u);
  EXPECT_GT(grid_rows, 2u * 40u);
  EXPECT_NEAR(deepest_mm, paper_depth_mm(0.0, 3.0), 1e-6);
}

TEST(SheetProfileCommand, ASceneWithoutASheetIsOneLineAndExit2) {
  const test::RunResult r =
      test::run_hapsim("sheet-profile " + std::string(HAPSIM_SCENES_DIR) + "/csg_block.json");
  EXPECT_EQ(r.exit_code, 2) << r.output;
  EXPECT_NE(r.output.find("no virtual sheet"), std::string::npos) << r.output;
}

}  // namespace
}  // namespace hapsim
