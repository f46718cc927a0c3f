// Posing the glove's hand for a scripted press or grasp: the glove angles that put one finger's
// tip on a goal (reach_with_finger), the hand position and angles that put several fingertips on
// their goals at once (solve_hand_pose), and the glove sample that plays a pose (glove_input).
// The glove plans (script/glove_palpation_plan.h, script/glove_pick_and_place_plan.h) use them.
#pragma once

#include "hapsim/core/device_io.h"
#include "hapsim/core/types.h"
#include "hapsim/kinematics/hand_model.h"

#include <array>
#include <cstddef>
#include <vector>

namespace hapsim {

/// One finger's glove angles: abduction, MCP, PIP (the DIP is coupled).
using GloveAngles = std::array<double, kGloveAnglesPerFinger>;

/// One glove sample: the tracker at `p_world` turned by R, every finger's three angles.
[[nodiscard]] DeviceInput glove_input(double time_s, const Vec3& p_world, const Mat3& R,
                                      const std::array<GloveAngles, kHandFingers>& angles);

struct HandPoseSolution {
  Vec3 p_world = Vec3::Zero();
  std::array<GloveAngles, kHandFingers> angles{};
  double worst_m = 0.0;         ///< the largest fingertip miss
  std::size_t worst_index = 0;  ///< which of the listed fingers missed most
};

/// Glove angles (abduction, MCP, PIP) putting finger f's tip at `goal_hand` (hand frame): damped
/// Gauss–Newton on the three angles with the DIP coupled, from a slightly curled start.
/// `*residual_m`: how far the tip stays from the goal.
[[nodiscard]] std::array<double, kGloveAnglesPerFinger> reach_with_finger(const HandModel& hand,
                                                                          int f,
                                                                          const Vec3& goal_hand,
                                                                          double* residual_m);

/// The hand position and the listed fingers' glove angles that put each finger's tip centre on its
/// goal (world) with the hand turned by R; the other fingers curled out of the way. The fingertips'
/// centroid (slightly curled) starts on the goals' centroid; then each finger's angles are solved,
/// the hand shifted by the fingers' mean miss, and the angles solved again (a few rounds).
[[nodiscard]] HandPoseSolution solve_hand_pose(const HandModel& hand, const Mat3& R,
                                               const std::vector<int>& fingers,
                                               const std::vector<Vec3>& goals);

}  // namespace hapsim
