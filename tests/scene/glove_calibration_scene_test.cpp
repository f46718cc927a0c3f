// A calibrated glove in a scene (docs/glove-calibration.md): the shipped example's raw palpation
// played through its user's calibration gives the angles and hand pose it was synthesized from
// (examples/glove_calibration/make_example.py, 1 count of noise), and every misuse — a
// calibration on a stylus or with a glove script, a missing or malformed USER.json, raw columns
// without a calibration, angles with one — is one error naming the file and the JSON pointer.
#include "hapsim/core/error.h"
#include "hapsim/scene/glove_calibration_file.h"
#include "hapsim/scene/scene_device.h"
#include "hapsim/scene/scene_file.h"

#include "support/temp_dir_test.h"

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <numbers>
#include <sstream>
#include <string>

namespace hapsim {
namespace {

namespace fs = std::filesystem;
using Json = nlohmann::json;

const fs::path kExample = fs::path(HAPSIM_SOURCE_DIR) / "examples" / "glove_calibration";

std::string read(const fs::path& p) {
  std::ifstream in(p);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

class GloveCalibrationScene : public test::TempDirTest {
 protected:
  Json example_scene() const { return Json::parse(read(kExample / "scene.json")); }

  // The example's scene with its files copied beside it, `edit` applied; its path.
  fs::path scene_with(const std::function<void(Json&)>& edit) const {
    for (const char* f : {"user.json", "palpation_raw.csv", "palpation_angles.csv"}) {
      fs::copy_file(kExample / f, dir_ / f, fs::copy_options::overwrite_existing);
    }
    Json j = example_scene();
    edit(j);
    return write("scene.json", j.dump(2));
  }

  void expect_error(const fs::path& scene, const std::string& where, const std::string& fragment,
                    bool at_device_creation = false) const {
    try {
      const SceneDescription s = load_scene(scene);
      if (at_device_creation) {
        const World world(s.world);
        (void)make_scene_device(s, world);
      }
      ADD_FAILURE() << "no error; expected " << where << ": " << fragment;
    } catch (const Error& e) {
      EXPECT_EQ(e.where(), where) << e.what();
      EXPECT_NE(e.detail().find(fragment), std::string::npos) << e.what();
    }
  }
};

TEST_F(GloveCalibrationScene, RawPalpationThroughTheCalibrationGivesTheAnglesItWasMadeFrom) {
  const SceneDescription scene = load_scene(kExample / "scene.json");
  ASSERT_TRUE(scene.device.glove_calibration.has_value());
  const World world(scene.world);
  auto device = make_scene_device(scene, world);
  const Trajectory angles = load_trajectory_csv(kExample / "palpation_angles.csv");
  // The noise, 1 count, through the calibration's inverse is 0.5-1 deg per joint (the residuals
  // user.json reports); over 401 rows the RMS must stay within 1.5 deg and no row 5 deg away
  // (5 sigma). The tracker's 0.3 mm noise and the pivot fit's error: within 2 mm.
  constexpr double kRadToDeg = 180.0 / std::numbers::pi;
  std::array<double, kGloveJoints> sum_sq{};
  double worst_deg = 0.0;
  double worst_p_m = 0.0;
  for (const DeviceInput& want : angles.samples) {
    const DeviceInput got = device->read(want.time_s);
    for (int j = 0; j < kGloveJoints; ++j) {
      const double e = (got.joint_rad[static_cast<std::size_t>(j)] -
                        want.joint_rad[static_cast<std::size_t>(j)]) *
                       kRadToDeg;
      sum_sq[static_cast<std::size_t>(j)] += e * e;
      worst_deg = std::max(worst_deg, std::abs(e));
    }
    worst_p_m = std::max(worst_p_m, (got.p_world - want.p_world).norm());
    EXPECT_LT(got.q_world.angularDistance(want.q_world), 1e-6);
  }
  double worst_rms = 0.0;
  for (int j = 0; j < kGloveJoints; ++j) {
    const double rms =
        std::sqrt(sum_sq[static_cast<std::size_t>(j)] / static_cast<double>(angles.size()));
    EXPECT_LT(rms, 1.5) << glove_joint_label(j);
    worst_rms = std::max(worst_rms, rms);
  }
  EXPECT_LT(worst_deg, 5.0);
  EXPECT_LT(worst_p_m, 2e-3);
  std::printf("example: worst joint RMS %.3f deg, worst %.3f deg, hand position within %.2f mm\n",
              worst_rms, worst_deg, worst_p_m * 1e3);
}

TEST_F(GloveCalibrationScene, MisusesAreOneErrorNamingTheFileAndPointer) {
  {
    const fs::path s = scene_with([](Json& j) {
      j["device"]["type"] = "simulated";
      j["tools"][0].erase("finger");
    });
    expect_error(s, s.string() + ":/device/calibration", "needs \"type\": \"glove\"");
  }
  {
    const fs::path s = scene_with([](Json& j) { j["device"]["calibration"] = "nobody.json"; });
    expect_error(s, s.string() + ":/device/calibration", "nobody.json");
  }
  {
    const fs::path s = scene_with([](Json& j) {
      j["device"].erase("trajectory");
      j["device"]["glove_palpation"] = Json::parse(
          R"({"from": [0, 0, 1], "fingers": [{"finger": 1, "body": "pad", "segment": "pad"}]})");
    });
    expect_error(s, s.string() + ":/device/calibration", "applies to a 'trajectory'");
  }
  {
    // A malformed calibration names its own file and pointer.
    const fs::path s = scene_with([](Json&) {});
    Json user = Json::parse(read(dir_ / "user.json"));
    user["sensors"][3]["gain_deg_per_count"] = 0;
    write("user.json", user.dump(2));
    expect_error(s, (dir_ / "user.json").string() + ":/sensors/3/gain_deg_per_count",
                 "non-zero gain");
    user = Json::parse(read(kExample / "user.json"));
    user["sensors"][11]["coupled_joint"] = "j5";
    write("user.json", user.dump(2));
    expect_error(s, (dir_ / "user.json").string() + ":/sensors/11/coupled_joint",
                 "expected \"j4\"");
    user = Json::parse(read(kExample / "user.json"));
    user["layout"] = "cyberglove-22";
    write("user.json", user.dump(2));
    expect_error(s, (dir_ / "user.json").string() + ":/layout", "hapsim-glove-14/1");
  }
  {
    const fs::path s = scene_with([](Json& j) { j["device"].erase("calibration"); });
    expect_error(s, (dir_ / "palpation_raw.csv").string(), "need a glove calibration", true);
  }
  {
    const fs::path s =
        scene_with([](Json& j) { j["device"]["trajectory"] = "palpation_angles.csv"; });
    expect_error(s, (dir_ / "palpation_angles.csv").string(), "would be ignored", true);
  }
}

TEST(GloveCalibrationFile, WrittenCalibrationReadsBackExactly) {
  const GloveCalibration c = load_glove_calibration(kExample / "user.json");
  const Json again = glove_calibration_json(c, "raw_procedure.csv", "procedure.json");
  const GloveCalibration d = parse_glove_calibration(again.dump(), "again.json");
  for (int s = 0; s < kGloveSensors; ++s) {
    const auto i = static_cast<std::size_t>(s);
    // Degrees and back: within a few ulps.
    EXPECT_NEAR(d.sensors[i].gain_rad_per_count, c.sensors[i].gain_rad_per_count,
                1e-15 * std::abs(c.sensors[i].gain_rad_per_count));
    EXPECT_EQ(d.sensors[i].offset_counts, c.sensors[i].offset_counts);
    EXPECT_EQ(d.sensors[i].coupling, c.sensors[i].coupling);
  }
  EXPECT_EQ(d.p_tracker_hand, c.p_tracker_hand);
  ASSERT_EQ(d.residuals.size(), c.residuals.size());
  for (std::size_t i = 0; i < c.residuals.size(); ++i) {
    EXPECT_EQ(d.residuals[i].joint, c.residuals[i].joint);
    EXPECT_EQ(d.residuals[i].rms_deg, c.residuals[i].rms_deg);
    // The layout's sensor for the joint: j3 (index abduction) is read by s11, the spread.
    if (c.residuals[i].joint == 3) {
      EXPECT_EQ(c.residuals[i].sensor, 11);
    }
  }
  EXPECT_TRUE(c.palm_offset_fitted);
  EXPECT_EQ(c.pivot_samples, 200u);
}

TEST(GloveProcedureFile, ErrorsNameThePointer) {
  const auto error_of = [](const std::string& text) {
    try {
      (void)parse_glove_procedure(text, "proc.json");
    } catch (const Error& e) {
      return e.where() + ": " + e.detail();
    }
    return std::string("(no error)");
  };
  EXPECT_NE(error_of(R"({"format": "hapsim-glove-procedure/1", "poses": [
      {"name": "fist", "from_s": 1, "to_s": 2, "angles_deg": {"j15": 3}}]})")
                .find("proc.json:/poses/0/angles_deg/j15: unknown joint 'j15'"),
            std::string::npos);
  EXPECT_NE(error_of(R"({"format": "hapsim-glove-procedure/1", "poses": [
      {"name": "fist", "from_s": 2, "to_s": 1, "angles_deg": {}}]})")
                .find("proc.json:/poses/0/to_s"),
            std::string::npos);
  EXPECT_NE(error_of(R"({"format": "hapsim-glove-procedure/1", "poses": [
      {"name": "a", "from_s": 1, "to_s": 2, "angles_deg": {}}], "pivot": {"from_s": 3, "to_s": 4},
      "tracker_to_hand": {"position_m": [0, 0, 0]}})")
                .find("proc.json:/tracker_to_hand/position_m"),
            std::string::npos);
  EXPECT_NE(
      error_of(R"({"format": "hapsim-glove-procedure/2", "poses": []})").find("proc.json:/format"),
      std::string::npos);
}

}  // namespace
}  // namespace hapsim
