// `hapsim run scenes/fem_block.json` through the real binary (issue 29's "done means"): the
// summary and JSON name the FEM body and its updates, the final picture shows the dent (the
// block's top is drawn lower under the fingertip than at its corners), and `--colours stress`
// draws the loaded tissue red with the scale in the summary.
#include "hapsim_process.h"

#include "hapsim/render/png_image.h"

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <fstream>
#include <string>

namespace hapsim {
namespace {

const std::string kBlock = std::string(HAPSIM_SCENES_DIR) + "/fem_block.json";

TEST(FemRun, TheBlockIsPressedAndItsSummarySaysHowTheFemRan) {
  const auto json = test::temp_path("fem.json");
  const auto r = test::run_hapsim("run " + kBlock + " -q --json " + json.string());
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_NE(r.output.find("fem   block   6912 tets, 1547 nodes, corotational"), std::string::npos)
      << r.output;
  std::ifstream in(json);
  const nlohmann::json j = nlohmann::json::parse(in);
  ASSERT_TRUE(j.contains("fem")) << j.dump(2);
  const auto& fem = j["fem"];
  EXPECT_EQ(fem["period_steps"].get<int>(), 10);
  EXPECT_EQ(fem["updates"].get<int>(), 720);  // 7.2 s at 100 Hz
  EXPECT_EQ(fem["late_adopted"].get<int>(), 0);
  EXPECT_EQ(fem["failures"].get<int>(), 0);
  // The run ends holding the fingertip 8 mm into the top: the block gave way by about that much.
  EXPECT_GT(fem["bodies"][0]["final_max_displacement_m"].get<double>(), 0.005);
  EXPECT_EQ(j["pop_throughs"].get<int>(), 0);
}

TEST(FemRun, StressColoursDrawTheLoadedTissueRedAndSayTheScale) {
  const auto png = test::temp_path("fem_stress.png");
  const auto r = test::run_hapsim("run " + kBlock + " -q --view dent --colours stress --size " +
                                  "640x360 --snapshot " + png.string());
  ASSERT_EQ(r.exit_code, 0) << r.output;
  const auto at = r.output.find("stress       FEM von Mises drawn red at ");
  ASSERT_NE(at, std::string::npos) << r.output;
  EXPECT_GT(std::stod(r.output.substr(at + 41)), 1.0) << "kPa: " << r.output;
  const RgbaImage image = read_png(png.string());
  // Red and orange pixels (the most loaded tissue) exist, and only a few: around the fingertip.
  int red = 0;
  for (std::size_t i = 0; i < image.rgba.size(); i += 4) {
    const int R = image.rgba[i];
    const int G = image.rgba[i + 1];
    const int B = image.rgba[i + 2];
    red += (R > 150 && G < 140 && B < 80) ? 1 : 0;
  }
  EXPECT_GT(red, 20);
  EXPECT_LT(red, 640 * 360 / 10);
  // Without stress colours the block has none of them.
  const auto plain = test::temp_path("fem_plain.png");
  const auto r2 = test::run_hapsim("run " + kBlock + " -q --view dent --size 640x360 --snapshot " +
                                   plain.string());
  ASSERT_EQ(r2.exit_code, 0) << r2.output;
  const RgbaImage image2 = read_png(plain.string());
  int red2 = 0;
  for (std::size_t i = 0; i < image2.rgba.size(); i += 4) {
    red2 += (image2.rgba[i] > 150 && image2.rgba[i + 1] < 140 && image2.rgba[i + 2] < 80) ? 1 : 0;
  }
  EXPECT_LT(red2, red / 4);
}

}  // namespace
}  // namespace hapsim
