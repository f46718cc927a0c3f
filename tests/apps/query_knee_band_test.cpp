// `hapsim query --method knee`'s error line compares only points within 10 mm of the surface, on
// either side, and says how many it left out: the centre of builtin:box (20 mm inside) is not
// "within 10 mm of the surface".
#include "apps/hapsim_process.h"

#include <nlohmann/json.hpp>

#include <fstream>
#include <string>

#include <gtest/gtest.h>

namespace hapsim {
namespace {

TEST(QueryKneeBand, DeepInsidePointsAreNotWithinTheBand) {
  // builtin:box spans ±50 x ±30 x ±20 mm: the centre is 20 mm deep, (0, 0, 15 mm) 5 mm deep,
  // (0, 0, 25 mm) 5 mm out and (0.3 m, 0, 0) far out.
  const auto points = test::temp_path("knee_band_points.csv");
  std::ofstream(points) << "x,y,z\n0,0,0\n0,0,0.015\n0,0,0.025\n0.3,0,0\n";
  const auto json = test::temp_path("knee_band.json");
  const auto out = test::temp_path("knee_band_out.csv");
  const auto r = test::run_hapsim("query builtin:box --method knee --points " + points.string() +
                                  " --out " + out.string() + " --json " + json.string());
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_NE(r.output.find("on the 2 points within 10 mm of the surface, inside or out (2 deeper "
                          "inside or farther out not compared)"),
            std::string::npos)
      << r.output;
  std::ifstream in(json);
  const nlohmann::json j = nlohmann::json::parse(in);
  EXPECT_EQ(j.at("error_vs_exact").at("points").get<std::size_t>(), 2u);
  EXPECT_EQ(j.at("error_vs_exact").at("not_compared").get<std::size_t>(), 2u);
}

}  // namespace
}  // namespace hapsim
