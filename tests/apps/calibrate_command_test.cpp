// `hapsim calibrate glove`: on the shipped example it prints every measured joint's residual and
// writes a USER.json that reads back; a dead sensor, a missing pose, a bad residual threshold, a
// NaN in the recording are each one line and exit 2, with nothing written to --out.
#include "hapsim_process.h"

#include "hapsim/scene/glove_calibration_file.h"

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

namespace hapsim {
namespace {

namespace fs = std::filesystem;

const fs::path kExample = fs::path(HAPSIM_SOURCE_DIR) / "examples" / "glove_calibration";

std::string args(const fs::path& raw, const fs::path& out, const std::string& extra = "") {
  return "calibrate glove " + raw.string() + " --procedure " +
         (kExample / "procedure.json").string() + " --out " + out.string() + " " + extra;
}

std::size_t lines(const std::string& s) {
  std::size_t n = 0;
  for (const char c : s) {
    n += c == '\n' ? 1 : 0;
  }
  return n;
}

// The example's recording with column `sensor` replaced by `value` on every row (a dead sensor),
// or with row `nan_row`'s first count made "nan".
fs::path edited_raw(const std::string& name, int dead_sensor, int nan_row = -1) {
  std::ifstream in(kExample / "raw_procedure.csv");
  std::ostringstream out;
  std::string line;
  int data_row = -1;
  while (std::getline(in, line)) {
    if (line.empty() || line[0] == '#' || line[0] == 't') {
      out << line << "\n";
      continue;
    }
    ++data_row;
    std::vector<std::string> fields;
    std::stringstream ss(line);
    for (std::string f; std::getline(ss, f, ',');) {
      fields.push_back(f);
    }
    if (dead_sensor >= 0) {
      fields[8 + static_cast<std::size_t>(dead_sensor)] = "131";
    }
    if (data_row == nan_row) {
      fields[8] = "nan";
    }
    for (std::size_t i = 0; i < fields.size(); ++i) {
      out << (i ? "," : "") << fields[i];
    }
    out << "\n";
  }
  const fs::path p = test::temp_path(name);
  std::ofstream(p) << out.str();
  return p;
}

TEST(CalibrateCommand, ExampleFitsPrintsEveryJointAndWritesACalibration) {
  const fs::path out = test::temp_path("user.json");
  const fs::path report = test::temp_path("report.json");
  fs::remove(out);
  const test::RunResult r =
      test::run_hapsim(args(kExample / "raw_procedure.csv", out, "--json " + report.string()));
  ASSERT_EQ(r.exit_code, 0) << r.output;
  for (int j = 0; j < 15; ++j) {
    if (j != 6) {
      EXPECT_NE(r.output.find(glove_joint_label(j) + " "), std::string::npos) << j << r.output;
    }
  }
  EXPECT_NE(r.output.find("j6 (middle abduction)"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("not measured"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("tracker→hand pivot fit"), std::string::npos) << r.output;
  const GloveCalibration c = load_glove_calibration(out);
  ASSERT_EQ(c.residuals.size(), 14u);
  for (const GloveJointResidual& res : c.residuals) {
    EXPECT_LT(res.rms_deg, 2.0) << glove_joint_label(res.joint);
  }
  // The example's tracker sits at (-35, 0, -25) mm from the hand origin (make_example.py).
  EXPECT_LT((c.p_tracker_hand - Vec3(-0.035, 0.0, -0.025)).norm(), 1e-3);
  EXPECT_TRUE(fs::exists(report));
}

TEST(CalibrateCommand, DeadSensorIsOneLineExit2AndNothingWritten) {
  const fs::path out = test::temp_path("dead_user.json");
  fs::remove(out);
  const fs::path raw = edited_raw("dead_raw.csv", 7);
  const test::RunResult r = test::run_hapsim(args(raw, out));
  EXPECT_EQ(r.exit_code, 2) << r.output;
  EXPECT_EQ(lines(r.output), 1u) << r.output;
  EXPECT_NE(r.output.find(raw.string() + ": sensor s7 (ring MCP flexion) never moved"),
            std::string::npos)
      << r.output;
  EXPECT_FALSE(fs::exists(out));
}

TEST(CalibrateCommand, BadResidualNanAndOptionsAreOneLineExit2) {
  const fs::path out = test::temp_path("bad_user.json");
  fs::remove(out);
  // The example's residuals are about 1 deg RMS: a 0.1 deg limit refuses the worst joint.
  test::RunResult r =
      test::run_hapsim(args(kExample / "raw_procedure.csv", out, "--max-residual-deg 0.1"));
  EXPECT_EQ(r.exit_code, 2) << r.output;
  EXPECT_EQ(lines(r.output), 1u) << r.output;
  EXPECT_NE(r.output.find("fits badly: residual"), std::string::npos) << r.output;
  EXPECT_FALSE(fs::exists(out));
  r = test::run_hapsim(args(edited_raw("nan_raw.csv", -1, 3), out));
  EXPECT_EQ(r.exit_code, 2) << r.output;
  EXPECT_NE(r.output.find("nan_raw.csv:7:"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("column 's0': expected a finite number"), std::string::npos) << r.output;
  r = test::run_hapsim(args(kExample / "raw_procedure.csv", out, "--max-residual-deg nan"));
  EXPECT_EQ(r.exit_code, 2) << r.output;
  EXPECT_NE(r.output.find("--max-residual-deg"), std::string::npos) << r.output;
  r = test::run_hapsim("calibrate glove " + (kExample / "raw_procedure.csv").string() +
                       " --procedure " + (kExample / "scene.json").string() + " --out " +
                       out.string());
  EXPECT_EQ(r.exit_code, 2) << r.output;
  EXPECT_NE(r.output.find("scene.json:/format"), std::string::npos) << r.output;
  EXPECT_FALSE(fs::exists(out));
}

}  // namespace
}  // namespace hapsim
