// `hapsim fk` and `hapsim ik` as a user runs them: a planar two-link URDF whose answers are known
// by hand, the GP7 when the data is there, and every bad input one named line with exit status 2.
#include "hapsim_process.h"
#include "support/test_data.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <string>

namespace {

using hapsim::test::read_csv_numbers;
using hapsim::test::run_hapsim;
using hapsim::test::RunResult;
using hapsim::test::temp_path;
using hapsim::test::write_file;

// Two links of 0.3 m and 0.2 m turning about z, the tip 0.2 m past the elbow.
const char* kPlanarUrdf = R"(<?xml version="1.0"?>
<robot name="planar">
  <link name="base"/><link name="upper"/><link name="fore"/><link name="tip"/>
  <joint name="shoulder" type="revolute"><parent link="base"/><child link="upper"/>
    <axis xyz="0 0 1"/><limit lower="-3" upper="3" effort="1" velocity="1"/></joint>
  <joint name="elbow" type="revolute"><parent link="upper"/><child link="fore"/>
    <origin xyz="0.3 0 0"/><axis xyz="0 0 1"/><limit lower="-3" upper="3" effort="1" velocity="1"/></joint>
  <joint name="tool" type="fixed"><parent link="fore"/><child link="tip"/><origin xyz="0.2 0 0"/></joint>
</robot>
)";

TEST(KinematicsCommands, ForwardThenInverseOnAPlanarArm) {
  const auto urdf = write_file("planar.urdf", kPlanarUrdf);
  const auto joints = write_file("joints.csv", "shoulder,elbow\n0,0\n0.5,-1.0\n1.2,0.4\n");
  const auto poses = temp_path("poses.csv");
  RunResult r = run_hapsim("fk " + urdf.string() + " --joints " + joints.string() + " --out " +
                           poses.string());
  ASSERT_EQ(r.exit_code, 0) << r.output;
  const auto rows = read_csv_numbers(poses);
  ASSERT_EQ(rows.size(), 3u);
  const double q[3][2] = {{0, 0}, {0.5, -1.0}, {1.2, 0.4}};
  for (int k = 0; k < 3; ++k) {
    const double a = q[k][0], b = q[k][1];
    EXPECT_NEAR(rows[k][0], 0.3 * std::cos(a) + 0.2 * std::cos(a + b), 1e-15);
    EXPECT_NEAR(rows[k][1], 0.3 * std::sin(a) + 0.2 * std::sin(a + b), 1e-15);
    EXPECT_NEAR(rows[k][2], 0.0, 1e-15);
    // A rotation by a + b about z: (cos, 0, 0, sin) of the half angle.
    EXPECT_NEAR(rows[k][3], std::cos((a + b) / 2), 1e-15);
    EXPECT_NEAR(rows[k][6], std::sin((a + b) / 2), 1e-15);
  }
  // Back again: each pose reached, and the joints reproduce it (checked by fk once more).
  const auto answers = temp_path("answers.csv");
  r = run_hapsim("ik " + urdf.string() + " --poses " + poses.string() + " --out " +
                 answers.string());
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_NE(r.output.find("3 reached"), std::string::npos) << r.output;
  const auto solved = read_csv_numbers(answers);
  ASSERT_EQ(solved.size(), 3u);
  for (int k = 0; k < 3; ++k) {
    ASSERT_EQ(solved[k].size(), 3u);
    EXPECT_EQ(solved[k][2], 1.0) << k;  // reached
    const double a = solved[k][0], b = solved[k][1];
    EXPECT_NEAR(0.3 * std::cos(a) + 0.2 * std::cos(a + b), rows[k][0], 1e-4);
    EXPECT_NEAR(0.3 * std::sin(a) + 0.2 * std::sin(a + b), rows[k][1], 1e-4);
  }
  // Out of reach (0.5 m is the longest the arm gets): reached = 0, still exit 0.
  const auto far = write_file("far.csv", "x,y,z,qw,qx,qy,qz\n0.7,0,0,1,0,0,0\n");
  r = run_hapsim("ik " + urdf.string() + " --poses " + far.string() + " --out " + answers.string());
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_EQ(read_csv_numbers(answers).at(0).at(2), 0.0);
  EXPECT_NE(r.output.find("1 unreachable"), std::string::npos) << r.output;
}

TEST(KinematicsCommands, Gp7HomePose) {
  const auto urdf = hapsim::test::data_path("motoman_gp7/gp7.urdf");
  HAPSIM_SKIP_WITHOUT_DATA(std::filesystem::exists(urdf), "Motoman GP7 URDF not found at " << urdf);
  const auto joints = write_file("gp7.csv", "0,0,0,0,0,0\n");
  const auto out = temp_path("gp7_pose.csv");
  const RunResult r = run_hapsim("fk " + urdf.string() + " --joints " + joints.string() +
                                 " --tip tool0 --out " + out.string());
  ASSERT_EQ(r.exit_code, 0) << r.output;
  const auto rows = read_csv_numbers(out);
  ASSERT_EQ(rows.size(), 1u);
  EXPECT_NEAR(rows[0][0], 0.56, 1e-12);  // joint origins added up by hand (URDF)
  EXPECT_NEAR(rows[0][2], 0.815, 1e-12);
}

TEST(KinematicsCommands, BadInputsAreOneNamedLineAndExitTwo) {
  const auto urdf = write_file("planar2.urdf", kPlanarUrdf);
  const auto broken = write_file("broken.urdf", "<robot name=\"x\"><link name=\"a\">");
  const auto three = write_file("three.csv", "1,2,3\n");
  const auto joints = write_file("ok.csv", "0,0\n");
  const auto skew = write_file("skew.csv", "0.3,0,0,2,0,0,0\n");
  const auto nan = write_file("nan.csv", "0,nan\n");
  struct Case {
    std::string args;
    std::string names;
  };
  const Case cases[] = {
      {"fk /nonexistent/r.urdf --joints " + joints.string(), "/nonexistent/r.urdf"},
      {"fk " + broken.string() + " --joints " + joints.string(), "broken.urdf"},
      {"fk " + urdf.string() + " --joints /nonexistent/j.csv", "/nonexistent/j.csv"},
      {"fk " + urdf.string() + " --joints " + three.string(), "three.csv:1"},
      {"fk " + urdf.string() + " --joints " + nan.string(), "nan.csv:1"},
      {"fk " + urdf.string() + " --joints " + joints.string() + " --tip hand", "'hand'"},
      {"ik " + urdf.string() + " --poses " + joints.string(), "ok.csv:1"},
      {"ik " + urdf.string() + " --poses " + skew.string(), "unit quaternion"},
      {"ik " + urdf.string(), "--poses"},
  };
  for (const Case& c : cases) {
    SCOPED_TRACE(c.args);
    const RunResult r = run_hapsim(c.args);
    EXPECT_EQ(r.exit_code, 2) << r.output;
    EXPECT_NE(r.output.find(c.names), std::string::npos) << r.output;
    EXPECT_EQ(std::count(r.output.begin(), r.output.end(), '\n'), 1) << r.output;
  }
}

}  // namespace
