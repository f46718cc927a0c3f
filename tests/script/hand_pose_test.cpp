// Posing the glove's hand for a scripted press or grasp (script/hand_pose.h): one finger's angles
// reach a goal the finger can reach, a common hand pose puts two fingertips on theirs, and a glove
// sample carries the pose and every finger's angles in the layout the world reads.
#include "hapsim/script/hand_pose.h"

#include <gtest/gtest.h>

#include <cstddef>
#include <vector>

namespace hapsim {
namespace {

Vec3 tip_hand(const HandModel& hand, int f, const GloveAngles& a) {
  return hand.finger(f).forward(hand.finger_joints(f, a)).translation();
}

TEST(HandPose, ReachWithFingerFindsAnglesThatPutTheTipOnAReachableGoal) {
  const HandModel hand;
  for (const int f : {0, 1, 4}) {
    SCOPED_TRACE(f);
    const GloveAngles wanted{0.1, 0.6, 0.8};
    const Vec3 goal = tip_hand(hand, f, wanted);
    double residual = -1.0;
    const GloveAngles a = reach_with_finger(hand, f, goal, &residual);
    EXPECT_LT(residual, 1e-6);
    EXPECT_NEAR((tip_hand(hand, f, a) - goal).norm(), residual, 1e-12);
  }
}

TEST(HandPose, SolveHandPosePutsThumbAndIndexOnTheirGoals) {
  const HandModel hand;
  // The goals of a hand at p0 (turned by R) with thumb and index half curled: reachable together.
  const Mat3 R = Eigen::AngleAxisd(0.3, Vec3::UnitZ()).toRotationMatrix();
  const Vec3 p0(0.1, -0.2, 0.3);
  std::vector<Vec3> goals;
  for (const int f : {0, 1}) {
    goals.push_back(p0 + R * tip_hand(hand, f, {0.05, 0.5, 0.6}));
  }
  const HandPoseSolution s = solve_hand_pose(hand, R, {0, 1}, goals);
  EXPECT_LT(s.worst_m, 1e-4);
  // The glove sample of that pose places the fingertips (as the world does) on the goals.
  const DeviceInput in = glove_input(0.25, s.p_world, R, s.angles);
  Iso3 X = Iso3::Identity();
  X.linear() = in.q_world.toRotationMatrix();
  X.translation() = in.p_world;
  const auto tips = hand.fingertips_world(
      glove_reading(X, {in.joint_rad.data(), static_cast<std::size_t>(in.joint_count)}));
  EXPECT_LT((tips[0] - goals[0]).norm(), 1e-3);
  EXPECT_LT((tips[1] - goals[1]).norm(), 1e-3);
  // The fingers not listed stay curled out of the way.
  EXPECT_DOUBLE_EQ(s.angles[2][1], 1.4);
  EXPECT_DOUBLE_EQ(s.angles[4][2], 1.7);
}

TEST(HandPose, GloveInputCarriesThePoseAndEveryFingersAngles) {
  std::array<GloveAngles, kHandFingers> angles{};
  for (std::size_t f = 0; f < angles.size(); ++f) {
    for (std::size_t k = 0; k < angles[f].size(); ++k) {
      angles[f][k] = 0.1 * static_cast<double>(f) + 0.01 * static_cast<double>(k);
    }
  }
  const Mat3 R = Eigen::AngleAxisd(0.7, Vec3(1, 2, 3).normalized()).toRotationMatrix();
  const DeviceInput in = glove_input(1.5, Vec3(1, 2, 3), R, angles);
  EXPECT_DOUBLE_EQ(in.time_s, 1.5);
  EXPECT_EQ(in.p_world, Vec3(1, 2, 3));
  EXPECT_LT((in.q_world.toRotationMatrix() - R).norm(), 1e-12);
  ASSERT_EQ(in.joint_count, kHandFingers * kGloveAnglesPerFinger);
  EXPECT_DOUBLE_EQ(in.joint_rad[3 * 4 + 2], angles[4][2]);
  EXPECT_DOUBLE_EQ(in.joint_rad[3 * 1 + 0], angles[1][0]);
}

}  // namespace
}  // namespace hapsim
