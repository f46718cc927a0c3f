#include "hapsim/script/hand_pose.h"

#include <algorithm>

namespace hapsim {

DeviceInput glove_input(double time_s, const Vec3& p_world, const Mat3& R,
                        const std::array<GloveAngles, kHandFingers>& angles) {
  DeviceInput in;
  in.time_s = time_s;
  in.p_world = p_world;
  in.q_world = Quat(R);
  in.joint_count = kHandFingers * kGloveAnglesPerFinger;
  for (int f = 0; f < kHandFingers; ++f) {
    for (int k = 0; k < kGloveAnglesPerFinger; ++k) {
      in.joint_rad[static_cast<std::size_t>(f) * kGloveAnglesPerFinger +
                   static_cast<std::size_t>(k)] =
          angles[static_cast<std::size_t>(f)][static_cast<std::size_t>(k)];
    }
  }
  return in;
}

std::array<double, kGloveAnglesPerFinger> reach_with_finger(const HandModel& hand, int f,
                                                            const Vec3& goal_hand,
                                                            double* residual_m) {
  std::array<double, kGloveAnglesPerFinger> a{0.0, 0.35, 0.45};
  // Returns a Vec3, not `auto`: translation() is a view into the temporary transform, which is gone
  // when the lambda returns (a stack-use-after-return under AddressSanitizer).
  const auto tip = [&](const std::array<double, kGloveAnglesPerFinger>& angles) -> Vec3 {
    return hand.finger(f).forward(hand.finger_joints(f, angles)).translation();
  };
  for (int it = 0; it < 60; ++it) {
    const Vec3 e = goal_hand - tip(a);
    if (e.norm() < 1e-7) {
      break;
    }
    Eigen::Matrix3d J;
    for (int k = 0; k < 3; ++k) {
      auto b = a;
      b[static_cast<std::size_t>(k)] += 1e-6;
      J.col(k) = (tip(b) - tip(a)) / 1e-6;
    }
    const Vec3 step =
        (J.transpose() * J + 1e-6 * Eigen::Matrix3d::Identity()).ldlt().solve(J.transpose() * e);
    for (int k = 0; k < 3; ++k) {
      a[static_cast<std::size_t>(k)] += std::clamp(step[k], -0.2, 0.2);
    }
    a = [&] {  // stay inside the joint limits the hand applies
      const auto q = hand.finger_joints(f, a);
      return std::array<double, kGloveAnglesPerFinger>{q[0], q[1], q[2]};
    }();
  }
  *residual_m = (goal_hand - tip(a)).norm();
  return a;
}

HandPoseSolution solve_hand_pose(const HandModel& hand, const Mat3& R,
                                 const std::vector<int>& fingers, const std::vector<Vec3>& goals) {
  Vec3 tips_local = Vec3::Zero();
  Vec3 goals_centroid = Vec3::Zero();
  for (std::size_t i = 0; i < fingers.size(); ++i) {
    const int f = fingers[i];
    tips_local += hand.finger(f).forward(hand.finger_joints(f, {0.0, 0.35, 0.45})).translation();
    goals_centroid += goals[i];
  }
  tips_local /= static_cast<double>(fingers.size());
  goals_centroid /= static_cast<double>(fingers.size());
  HandPoseSolution out;
  out.p_world = goals_centroid - R * tips_local;
  for (int f = 0; f < kHandFingers; ++f) {
    out.angles[static_cast<std::size_t>(f)] = {0.0, 1.4, 1.7};
  }
  out.worst_m = kInf;
  for (int round = 0; round < 20 && out.worst_m > 1e-4; ++round) {
    Iso3 X_press = Iso3::Identity();
    X_press.linear() = R;
    X_press.translation() = out.p_world;
    Vec3 miss = Vec3::Zero();
    out.worst_m = 0.0;
    for (std::size_t i = 0; i < fingers.size(); ++i) {
      const int f = fingers[i];
      double residual = 0.0;
      out.angles[static_cast<std::size_t>(f)] =
          reach_with_finger(hand, f, X_press.inverse() * goals[i], &residual);
      const Vec3 tip =
          X_press * hand.finger(f)
                        .forward(hand.finger_joints(f, out.angles[static_cast<std::size_t>(f)]))
                        .translation();
      miss += goals[i] - tip;
      if (residual > out.worst_m) {
        out.worst_m = residual;
        out.worst_index = i;
      }
    }
    out.p_world += miss / static_cast<double>(fingers.size());
  }
  return out;
}

}  // namespace hapsim
