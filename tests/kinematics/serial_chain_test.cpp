// Forward kinematics and the Jacobian against answers worked out by hand (a planar arm, the GP7's
// joint origins read off its URDF) and against finite differences; URDF loading and its errors.
#include "hapsim/kinematics/serial_chain.h"
#include "hapsim/kinematics/dh_chain.h"
#include "hapsim/kinematics/urdf_chain.h"

#include "hapsim/core/error.h"
#include "support/test_data.h"

#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <numbers>
#include <random>
#include <vector>

#include <unistd.h>

namespace hapsim {
namespace {

namespace fs = std::filesystem;
constexpr double kPi = std::numbers::pi;

// The PUMA 560 (Craig's DH table, standard convention; metres).
SerialChain puma() {
  const std::vector<DhRow> rows{
      {.a_m = 0.0, .alpha_rad = kPi / 2, .d_m = 0.0, .lower = -2.8, .upper = 2.8},
      {.a_m = 0.4318, .alpha_rad = 0.0, .d_m = 0.0, .lower = -3.9, .upper = 0.8},
      {.a_m = 0.0203, .alpha_rad = -kPi / 2, .d_m = 0.15005, .lower = -0.8, .upper = 3.9},
      {.a_m = 0.0, .alpha_rad = kPi / 2, .d_m = 0.4318, .lower = -1.9, .upper = 2.9},
      {.a_m = 0.0, .alpha_rad = -kPi / 2, .d_m = 0.0, .lower = -1.7, .upper = 1.7},
      {.a_m = 0.0, .alpha_rad = 0.0, .d_m = 0.0, .lower = -4.6, .upper = 4.6},
  };
  return make_dh_chain(rows);
}

TEST(SerialChain, PlanarArmMatchesTheTextbook) {
  const std::vector<DhRow> rows{{.a_m = 0.3}, {.a_m = 0.2}};
  const SerialChain arm = make_dh_chain(rows);
  ASSERT_EQ(arm.dof(), 2);
  for (const auto& [q1, q2] : {std::pair{0.0, 0.0}, {0.3, -1.1}, {2.5, 0.7}, {-1.0, 3.0}}) {
    const std::array<double, 2> q{q1, q2};
    const Iso3 X = arm.forward(q);
    const Vec3 expected(0.3 * std::cos(q1) + 0.2 * std::cos(q1 + q2),
                        0.3 * std::sin(q1) + 0.2 * std::sin(q1 + q2), 0.0);
    EXPECT_NEAR((X.translation() - expected).norm(), 0.0, 1e-15);
    EXPECT_NEAR((X.linear() - Eigen::AngleAxisd(q1 + q2, Vec3::UnitZ()).toRotationMatrix()).norm(),
                0.0, 1e-15);
    // Jacobian of the planar arm, by hand: d(x,y)/dq and ω = (0, 0, 1) per joint.
    const ChainJacobian J = arm.jacobian(q);
    EXPECT_NEAR(J(0, 0), -0.3 * std::sin(q1) - 0.2 * std::sin(q1 + q2), 1e-15);
    EXPECT_NEAR(J(1, 0), 0.3 * std::cos(q1) + 0.2 * std::cos(q1 + q2), 1e-15);
    EXPECT_NEAR(J(0, 1), -0.2 * std::sin(q1 + q2), 1e-15);
    EXPECT_NEAR(J(1, 1), 0.2 * std::cos(q1 + q2), 1e-15);
    EXPECT_NEAR(J(5, 0), 1.0, 1e-15);
    EXPECT_NEAR(J(5, 1), 1.0, 1e-15);
  }
}

TEST(SerialChain, PrismaticJointSlidesAlongItsAxis) {
  // A vertical slide (d = q) then a 0.25 m horizontal link turning about z.
  const std::vector<DhRow> rows{{.type = JointType::kPrismatic, .lower = 0.0, .upper = 0.5},
                                {.a_m = 0.25}};
  const SerialChain arm = make_dh_chain(rows);
  const std::array<double, 2> q{0.3, kPi / 2};
  EXPECT_NEAR((arm.forward(q).translation() - Vec3(0.0, 0.25, 0.3)).norm(), 0.0, 1e-15);
  const ChainJacobian J = arm.jacobian(q);
  EXPECT_NEAR((J.col(0) - (Eigen::Matrix<double, 6, 1>() << 0, 0, 1, 0, 0, 0).finished()).norm(),
              0.0, 1e-15);
  EXPECT_TRUE(arm.within_limits(q));
  std::array<double, 2> out{0.7, std::nan("")};
  EXPECT_FALSE(arm.within_limits(out));
  arm.clamp_to_limits(out);
  EXPECT_EQ(out[0], 0.5);
  EXPECT_EQ(out[1], 0.0);  // NaN on an unlimited joint: 0
}

// The Jacobian is the derivative of the forward kinematics: central differences of the tip
// position and of the tip rotation (as a rotation vector) agree to 1e-7.
TEST(SerialChain, JacobianIsTheDerivativeOfForwardKinematics) {
  const SerialChain arm = puma();
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> u(-1.5, 1.5);
  for (int trial = 0; trial < 50; ++trial) {
    std::array<double, 6> q{};
    for (double& v : q) {
      v = u(rng);
    }
    const ChainJacobian J = arm.jacobian(q);
    const double h = 1e-6;
    for (int i = 0; i < 6; ++i) {
      std::array<double, 6> qp = q, qm = q;
      qp[static_cast<std::size_t>(i)] += h;
      qm[static_cast<std::size_t>(i)] -= h;
      const Iso3 Xp = arm.forward(qp), Xm = arm.forward(qm);
      const Vec3 v = (Xp.translation() - Xm.translation()) / (2 * h);
      const Eigen::AngleAxisd dR(Xp.linear() * Xm.linear().transpose());
      const Vec3 w = dR.angle() * dR.axis() / (2 * h);
      EXPECT_NEAR((J.block<3, 1>(0, i) - v).norm(), 0.0, 1e-7) << trial << " joint " << i;
      EXPECT_NEAR((J.block<3, 1>(3, i) - w).norm(), 0.0, 1e-7) << trial << " joint " << i;
    }
  }
}

TEST(SerialChain, BadJointsAreRefused) {
  ChainJoint j;
  j.name = "elbow";
  j.axis = Vec3::Zero();
  EXPECT_THROW(SerialChain("base", {j}, Iso3::Identity(), "tip"), Error);
  j.axis = Vec3::UnitZ();
  j.lower = 1.0;
  j.upper = -1.0;
  try {
    (void)SerialChain("base", {j}, Iso3::Identity(), "tip");
    ADD_FAILURE();
  } catch (const Error& e) {
    EXPECT_EQ(e.where(), "joint 'elbow'");
    EXPECT_NE(e.detail().find("lower <= upper"), std::string::npos);
  }
  std::vector<ChainJoint> many(kMaxChainJoints + 1, ChainJoint{});
  EXPECT_THROW(SerialChain("base", many, Iso3::Identity(), "tip"), Error);
}

fs::path gp7_urdf() {
  return test::data_path("motoman_gp7/gp7.urdf");
}

#define SKIP_WITHOUT_GP7() \
  HAPSIM_SKIP_WITHOUT_DATA(fs::exists(gp7_urdf()), "Motoman GP7 URDF not found at " << gp7_urdf())

// At q = 0 the GP7's joint origins (URDF) add up to tool0 at (0.04 + 0.44 + 0.08, 0,
// 0.33 + 0.445 + 0.04) with rpy (π, −π/2, 0); base rotation and the shoulder turn it as a rigid
// body about their axes.
TEST(UrdfChain, MotomanGp7MatchesItsJointOriginsByHand) {
  SKIP_WITHOUT_GP7();
  const SerialChain gp7 = load_urdf_chain(gp7_urdf());
  ASSERT_EQ(gp7.dof(), 6);
  EXPECT_EQ(gp7.base_link(), "base_link");
  EXPECT_EQ(gp7.tip_link(), "tool0");
  EXPECT_EQ(gp7.joints()[1].name, "joint_2_l");
  EXPECT_DOUBLE_EQ(gp7.joints()[1].lower, -1.1344);
  EXPECT_DOUBLE_EQ(gp7.joints()[1].upper, 2.5307);
  EXPECT_DOUBLE_EQ(gp7.joints()[5].max_velocity, 17.4845);

  std::array<double, 6> q{};
  const Iso3 home = gp7.forward(q);
  EXPECT_NEAR((home.translation() - Vec3(0.56, 0.0, 0.815)).norm(), 0.0, 1e-12);
  const Mat3 R_tool =
      (Eigen::AngleAxisd(0.0, Vec3::UnitZ()) * Eigen::AngleAxisd(-1.570796, Vec3::UnitY()) *
       Eigen::AngleAxisd(3.1415926, Vec3::UnitX()))
          .toRotationMatrix();
  EXPECT_NEAR((home.linear() - R_tool).norm(), 0.0, 1e-12);

  q = {kPi / 2, 0, 0, 0, 0, 0};  // base rotation about +z
  EXPECT_NEAR((gp7.forward(q).translation() - Vec3(0.0, 0.56, 0.815)).norm(), 0.0, 1e-12);

  const double t = 0.5;  // shoulder about +y at (0.04, 0, 0.33): rotates the rest (0.52, 0, 0.485)
  q = {0, t, 0, 0, 0, 0};
  const Vec3 arm(0.52, 0.0, 0.485);
  const Vec3 expected =
      Vec3(0.04, 0.0, 0.33) + Vec3(arm.x() * std::cos(t) + arm.z() * std::sin(t), 0.0,
                                   -arm.x() * std::sin(t) + arm.z() * std::cos(t));
  EXPECT_NEAR((gp7.forward(q).translation() - expected).norm(), 0.0, 1e-12);

  q = {0, 0, 0, 0.7, 0, 0};  // wrist roll about −x: the tool0 point stays on that axis
  EXPECT_NEAR((gp7.forward(q).translation() - Vec3(0.56, 0.0, 0.815)).norm(), 0.0, 1e-12);

  // Collision meshes of base_link and the six moving links, in metres (a GP7 is ~1 m tall).
  ASSERT_EQ(gp7.link_geometry().size(), 7u);
  EXPECT_EQ(gp7.link_geometry()[0].frame, -1);
  EXPECT_EQ(gp7.link_geometry()[6].frame, 5);
  for (const ChainLinkGeometry& g : gp7.link_geometry()) {
    EXPECT_GT(g.mesh.triangle_count(), 10u) << g.link;
    EXPECT_LT(g.mesh.bounds().diagonal().norm(), 1.0) << g.link;
  }
  EXPECT_EQ(gp7.frame_of_link("link_3_u"), 2);
  EXPECT_EQ(gp7.frame_of_link("nowhere"), -2);
}

TEST(UrdfChain, TipAndBaseCanBeChosen) {
  SKIP_WITHOUT_GP7();
  UrdfChainOptions o;
  o.base_link = "link_1_s";
  o.tip_link = "link_4_r";
  o.load_collision_meshes = false;
  const SerialChain part = load_urdf_chain(gp7_urdf(), o);
  ASSERT_EQ(part.dof(), 3);
  EXPECT_EQ(part.joints()[0].name, "joint_2_l");
  EXPECT_TRUE(part.link_geometry().empty());
}

class UrdfErrors : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() / ("hapsim_urdf_test_" + std::to_string(::getpid()));
    fs::create_directories(dir_);
  }
  void TearDown() override { fs::remove_all(dir_); }

  void expect_error(const std::string& xml, const std::string& fragment,
                    const UrdfChainOptions& options = {}) {
    const fs::path file = dir_ / "robot.urdf";
    std::ofstream(file) << xml;
    try {
      (void)load_urdf_chain(file, options);
      ADD_FAILURE() << "loaded; expected: " << fragment;
    } catch (const Error& e) {
      EXPECT_NE(std::string(e.what()).find(file.string()), std::string::npos) << e.what();
      EXPECT_NE(std::string(e.what()).find(fragment), std::string::npos) << e.what();
    }
  }

  static std::string robot(const std::string& body) {
    return "<?xml version=\"1.0\"?>\n<robot name=\"r\">\n" + body + "\n</robot>\n";
  }

  fs::path dir_;
};

const char* kTwoLinks = R"(
  <link name="base"/>
  <link name="arm"/>
  <joint name="j1" type="revolute">
    <parent link="base"/><child link="arm"/>
    <origin xyz="0 0 0.1" rpy="0 0 0"/><axis xyz="0 0 1"/>
    <limit lower="-1" upper="1" effort="1" velocity="1"/>
  </joint>)";

TEST_F(UrdfErrors, EachBrokenFileSaysWhatIsWrong) {
  expect_error("this is not xml", "not a valid URDF");
  expect_error("<robot name=\"r\"><link name=\"a\"/>", "not a valid URDF");  // unclosed
  expect_error(robot(R"(<link name="a"/><link name="b"/>
    <joint name="j" type="revolute"><parent link="a"/><child link="nope"/>
    <limit lower="0" upper="1" effort="1" velocity="1"/></joint>)"),
               "not a valid URDF");
  expect_error(robot(R"(<link name="a"/><link name="b"/>
    <joint name="free" type="floating"><parent link="a"/><child link="b"/></joint>)"),
               "joint 'free'");
  expect_error(robot(std::string(kTwoLinks) + R"(
    <link name="hand"><collision><geometry><mesh filename="missing.stl"/></geometry></collision></link>
    <joint name="j2" type="fixed"><parent link="arm"/><child link="hand"/></joint>)"),
               "missing.stl");
  expect_error(robot(R"(<link name="a"><collision><geometry>
      <mesh filename="package://robot/meshes/a.stl"/></geometry></collision></link>)"),
               "package://");
  UrdfChainOptions tip;
  tip.tip_link = "gripper";
  expect_error(robot(kTwoLinks), "no tip link 'gripper'", tip);
  // Two branches, equally deep: the tip must be chosen.
  expect_error(robot(std::string(kTwoLinks) + R"(
    <link name="other"/>
    <joint name="j3" type="continuous"><parent link="base"/><child link="other"/>
      <axis xyz="1 0 0"/></joint>)"),
               "several tip links");
  try {
    (void)load_urdf_chain(dir_ / "absent.urdf");
    ADD_FAILURE();
  } catch (const Error& e) {
    EXPECT_NE(e.detail().find("cannot open"), std::string::npos);
  }
}

TEST_F(UrdfErrors, PrimitivesAndContinuousJointsLoad) {
  const fs::path file = dir_ / "prim.urdf";
  std::ofstream(file) << robot(R"(
    <link name="base"><collision><geometry><box size="0.2 0.1 0.05"/></geometry></collision></link>
    <link name="arm"><collision><origin xyz="0 0 0.1"/>
      <geometry><cylinder radius="0.02" length="0.2"/></geometry></collision></link>
    <link name="ball"><collision><geometry><sphere radius="0.03"/></geometry></collision></link>
    <joint name="spin" type="continuous"><parent link="base"/><child link="arm"/>
      <axis xyz="0 0 2"/></joint>
    <joint name="slide" type="prismatic"><parent link="arm"/><child link="ball"/>
      <origin xyz="0 0 0.2"/><axis xyz="0 0 1"/>
      <limit lower="0" upper="0.1" effort="1" velocity="0.5"/></joint>)");
  const SerialChain c = load_urdf_chain(file);
  ASSERT_EQ(c.dof(), 2);
  EXPECT_EQ(c.joints()[0].type, JointType::kRevolute);
  EXPECT_TRUE(std::isinf(c.joints()[0].lower));  // continuous: unlimited
  EXPECT_EQ(c.joints()[0].axis, Vec3::UnitZ());  // normalised
  EXPECT_EQ(c.joints()[1].type, JointType::kPrismatic);
  EXPECT_EQ(c.joints()[1].max_velocity, 0.5);
  const std::array<double, 2> q{0.0, 0.05};
  EXPECT_NEAR((c.forward(q).translation() - Vec3(0, 0, 0.25)).norm(), 0.0, 1e-15);
  ASSERT_EQ(c.link_geometry().size(), 3u);
  const Box3 box = c.link_geometry()[0].mesh.bounds();
  EXPECT_NEAR(box.max().x(), 0.1, 1e-12);
  const Box3 cyl = c.link_geometry()[1].mesh.bounds();
  EXPECT_NEAR(cyl.max().z(), 0.1, 2e-3);
  EXPECT_NEAR(cyl.max().x(), 0.02, 2e-3);
  EXPECT_NEAR(c.link_geometry()[1].X_frame_mesh.translation().z(), 0.1, 1e-15);
  EXPECT_NEAR(c.link_geometry()[2].mesh.bounds().max().z(), 0.03, 1e-9);
}

}  // namespace
}  // namespace hapsim
