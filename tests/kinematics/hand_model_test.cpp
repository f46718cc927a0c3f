// The virtual hand: fingertips at known joint angles against positions worked out by hand (each
// phalanx a vector turned by the sum of the flexions before it), the DIP = ⅔·PIP coupling, the
// tracker pose, limits and bad input.
#include "hapsim/kinematics/hand_model.h"

#include "hapsim/core/error.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>

namespace hapsim {
namespace {

constexpr int kThumb = 0, kIndex = 1, kMiddle = 2;

Vec3 rz(double a, const Vec3& v) {
  return Eigen::AngleAxisd(a, Vec3::UnitZ()) * v;
}

TEST(HandModel, StraightFingersPointAlongTheirRestDirection) {
  const HandModel hand;
  const GloveReading flat;  // identity pose, all angles 0
  const auto tips = hand.fingertips_world(flat);
  for (int f = kIndex; f < kHandFingers; ++f) {
    const FingerGeometry& g = hand.geometry().fingers[static_cast<std::size_t>(f)];
    const double length = g.phalanx_m[0] + g.phalanx_m[1] + g.phalanx_m[2];
    const Vec3 expected = g.mcp_hand + rz(g.yaw_rad, Vec3(length, 0, 0));
    EXPECT_NEAR((tips[static_cast<std::size_t>(f)] - expected).norm(), 0.0, 1e-15) << f;
  }
}

// Middle finger curled in the x–z plane: MCP 0.5, PIP 0.9, so DIP = 0.6; each phalanx points at
// the sum of the flexions so far, downwards (towards the palm).
TEST(HandModel, CurledFingerMatchesHandComputation) {
  const HandModel hand;
  GloveReading r;
  r.angles_rad[kMiddle] = {0.0, 0.5, 0.9};
  const FingerGeometry& g = hand.geometry().fingers[kMiddle];
  const auto dir = [](double a) { return Vec3(std::cos(a), 0.0, -std::sin(a)); };
  const Vec3 expected = g.mcp_hand + g.phalanx_m[0] * dir(0.5) + g.phalanx_m[1] * dir(1.4) +
                        g.phalanx_m[2] * dir(1.4 + 0.6);
  EXPECT_NEAR((hand.fingertips_world(r)[kMiddle] - expected).norm(), 0.0, 1e-15);
  const auto q = hand.finger_joints(kMiddle, r.angles_rad[kMiddle]);
  EXPECT_DOUBLE_EQ(q[3], 0.6);  // DIP = ⅔·PIP
}

TEST(HandModel, AbductionSpreadsTheFingerAboutTheBackOfTheHand) {
  const HandModel hand;
  GloveReading r;
  r.angles_rad[kIndex] = {0.2, 0.0, 0.0};
  const FingerGeometry& g = hand.geometry().fingers[kIndex];
  const double length = g.phalanx_m[0] + g.phalanx_m[1] + g.phalanx_m[2];
  EXPECT_NEAR(
      (hand.fingertips_world(r)[kIndex] - (g.mcp_hand + rz(g.yaw_rad + 0.2, Vec3(length, 0, 0))))
          .norm(),
      0.0, 1e-15);
}

TEST(HandModel, CouplingRatioAndLimitsApply) {
  HandGeometry geometry;
  geometry.dip_per_pip = 0.5;
  const HandModel half(geometry);
  EXPECT_DOUBLE_EQ(half.finger_joints(kIndex, {0.0, 0.0, 1.0})[3], 0.5);
  geometry.dip_per_pip = 1.0;
  const HandModel one(geometry);
  const auto q = one.finger_joints(kIndex, {1.0, 9.0, 1.8});
  EXPECT_DOUBLE_EQ(q[0], geometry.fingers[kIndex].abduction_limit_rad);
  EXPECT_DOUBLE_EQ(q[1], geometry.fingers[kIndex].mcp_limit_rad);
  EXPECT_DOUBLE_EQ(q[2], 1.8);
  EXPECT_DOUBLE_EQ(q[3], geometry.fingers[kIndex].dip_limit_rad);  // 1.8 clamped to 1.4
  const double nan = std::numeric_limits<double>::quiet_NaN();
  const auto straight = one.finger_joints(kIndex, {nan, nan, nan});
  for (const double v : straight) {
    EXPECT_EQ(v, 0.0);
  }
}

TEST(HandModel, TrackerPosePlacesTheHandInTheWorld) {
  const HandModel hand;
  GloveReading local;
  local.angles_rad[kThumb] = {0.1, 0.4, 0.6};
  local.angles_rad[kIndex] = {0.0, 0.3, 0.5};
  GloveReading world = local;
  world.X_world_hand =
      Eigen::Translation3d(0.1, -0.2, 0.3) * Eigen::AngleAxisd(0.7, Vec3(1, 2, 3).normalized());
  const auto a = hand.fingertips_world(local);
  const auto b = hand.fingertips_world(world);
  for (int f = 0; f < kHandFingers; ++f) {
    EXPECT_NEAR(
        (b[static_cast<std::size_t>(f)] - world.X_world_hand * a[static_cast<std::size_t>(f)])
            .norm(),
        0.0, 1e-15);
  }
  std::array<Iso3, 4> frames;
  const Iso3 tip = hand.finger_frames_world(kIndex, world, frames);
  EXPECT_NEAR((tip.translation() - b[kIndex]).norm(), 0.0, 1e-15);
  // The first frame sits at the index MCP.
  EXPECT_NEAR(
      (frames[0].translation() - world.X_world_hand * hand.geometry().fingers[kIndex].mcp_hand)
          .norm(),
      0.0, 1e-15);
  GloveReading broken = local;
  broken.X_world_hand.translation().x() = std::numeric_limits<double>::infinity();
  EXPECT_EQ(hand.fingertips_world(broken)[kIndex], a[kIndex]);  // rest at the origin
}

TEST(HandModel, GloveJointsMapThreePerFinger) {
  std::array<double, 15> j{};
  for (std::size_t i = 0; i < j.size(); ++i) {
    j[i] = 0.01 * static_cast<double>(i);
  }
  const GloveReading r = glove_reading(Iso3::Identity(), j);
  EXPECT_DOUBLE_EQ(r.angles_rad[2][1], 0.07);  // finger 2, angle 1 = j7
  EXPECT_DOUBLE_EQ(r.angles_rad[4][2], 0.14);
  const GloveReading short_glove = glove_reading(Iso3::Identity(), std::span(j).first(4));
  EXPECT_DOUBLE_EQ(short_glove.angles_rad[1][0], 0.03);
  EXPECT_DOUBLE_EQ(short_glove.angles_rad[1][1], 0.0);  // missing: 0
}

TEST(HandModel, BadGeometryIsNamed) {
  HandGeometry g;
  g.fingers[3].phalanx_m[1] = 0.0;
  try {
    const HandModel hand(g);
    ADD_FAILURE();
  } catch (const Error& e) {
    EXPECT_EQ(e.where(), "hand finger 'ring'");
  }
  HandGeometry r;
  r.dip_per_pip = -1.0;
  EXPECT_THROW(HandModel{r}, Error);
}

}  // namespace
}  // namespace hapsim
