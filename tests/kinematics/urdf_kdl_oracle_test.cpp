// The GP7's forward kinematics and Jacobian against orocos-kdl (test oracle only): the test
// builds a KDL chain from urdfdom's model itself, the way kdl_parser does (a segment per joint:
// Joint(origin, axis) then the joint origin frame), so the only thing shared with hapsim is
// urdfdom's reading of the XML.
#include "hapsim/kinematics/urdf_chain.h"
#include "support/test_data.h"

#include <gtest/gtest.h>

#include <filesystem>
#include <random>

#ifdef HAPSIM_HAVE_KDL
#include <urdf_parser/urdf_parser.h>
#include <kdl/chain.hpp>
#include <kdl/chainfksolverpos_recursive.hpp>
#include <kdl/chainjnttojacsolver.hpp>
#include <kdl/frames.hpp>
#endif

namespace hapsim {
namespace {

namespace fs = std::filesystem;

#ifdef HAPSIM_HAVE_KDL
KDL::Frame to_kdl(const urdf::Pose& p) {
  return KDL::Frame(
      KDL::Rotation::Quaternion(p.rotation.x, p.rotation.y, p.rotation.z, p.rotation.w),
      KDL::Vector(p.position.x, p.position.y, p.position.z));
}

// kdl_parser's construction, for a single path from `base` to `tip`.
KDL::Chain kdl_chain(const urdf::ModelInterface& model, const std::string& base,
                     const std::string& tip) {
  std::vector<urdf::LinkConstSharedPtr> path;
  for (urdf::LinkConstSharedPtr l = model.getLink(tip); l && l->name != base; l = l->getParent()) {
    path.push_back(l);
  }
  std::reverse(path.begin(), path.end());
  KDL::Chain chain;
  for (const auto& link : path) {
    const urdf::JointSharedPtr& j = link->parent_joint;
    const KDL::Frame F = to_kdl(j->parent_to_joint_origin_transform);
    const KDL::Vector axis(j->axis.x, j->axis.y, j->axis.z);
    KDL::Joint joint;
    if (j->type == urdf::Joint::FIXED) {
      joint = KDL::Joint(j->name, KDL::Joint::None);
    } else if (j->type == urdf::Joint::PRISMATIC) {
      joint = KDL::Joint(j->name, F.p, F.M * axis, KDL::Joint::TransAxis);
    } else {
      joint = KDL::Joint(j->name, F.p, F.M * axis, KDL::Joint::RotAxis);
    }
    chain.addSegment(KDL::Segment(link->name, joint, F));
  }
  return chain;
}
#endif

TEST(KdlOracle, Gp7ForwardKinematicsAndJacobianAgree) {
#ifndef HAPSIM_HAVE_KDL
  GTEST_SKIP() << "orocos-kdl not found at configure time";
#else
  const fs::path urdf = test::data_path("motoman_gp7/gp7.urdf");
  HAPSIM_SKIP_WITHOUT_DATA(fs::exists(urdf), "Motoman GP7 URDF not found at " << urdf);
  UrdfChainOptions o;
  o.load_collision_meshes = false;
  const SerialChain ours = load_urdf_chain(urdf, o);
  const urdf::ModelInterfaceSharedPtr model = urdf::parseURDFFile(urdf.string());
  ASSERT_TRUE(model);
  const KDL::Chain theirs = kdl_chain(*model, "base_link", "tool0");
  ASSERT_EQ(static_cast<int>(theirs.getNrOfJoints()), ours.dof());
  KDL::ChainFkSolverPos_recursive fk(theirs);
  KDL::ChainJntToJacSolver jac(theirs);

  std::mt19937 rng(5);
  for (int trial = 0; trial < 500; ++trial) {
    KDL::JntArray q(6);
    std::vector<double> qv(6);
    for (int i = 0; i < 6; ++i) {
      const ChainJoint& j = ours.joints()[static_cast<std::size_t>(i)];
      qv[static_cast<std::size_t>(i)] =
          std::uniform_real_distribution<double>(j.lower, j.upper)(rng);
      q(i) = qv[static_cast<std::size_t>(i)];
    }
    KDL::Frame F;
    ASSERT_GE(fk.JntToCart(q, F), 0);
    const Iso3 X = ours.forward(qv);
    for (int r = 0; r < 3; ++r) {
      EXPECT_NEAR(X.translation()[r], F.p(r), 1e-12) << trial;
      for (int c = 0; c < 3; ++c) {
        EXPECT_NEAR(X.linear()(r, c), F.M(r, c), 1e-12) << trial;
      }
    }
    KDL::Jacobian J(6);
    ASSERT_GE(jac.JntToJac(q, J), 0);
    const ChainJacobian Jo = ours.jacobian(qv);
    for (int r = 0; r < 6; ++r) {
      for (int c = 0; c < 6; ++c) {
        EXPECT_NEAR(Jo(r, c), J(static_cast<unsigned>(r), static_cast<unsigned>(c)), 1e-12)
            << trial << " (" << r << "," << c << ")";
      }
    }
  }
#endif
}

}  // namespace
}  // namespace hapsim
