#include "hapsim/kinematics/hand_model.h"

#include "hapsim/core/error.h"

#include <cmath>
#include <string>

namespace hapsim {

namespace {

const char* const kFingerNames[kHandFingers] = {"thumb", "index", "middle", "ring", "little"};

FingerGeometry finger(const Vec3& mcp, double yaw, double roll, std::array<double, 3> lengths,
                      double tip_radius) {
  FingerGeometry g;
  g.mcp_hand = mcp;
  g.yaw_rad = yaw;
  g.roll_rad = roll;
  g.phalanx_m = lengths;
  g.tip_radius_m = tip_radius;
  return g;
}

SerialChain finger_chain(const FingerGeometry& g, int f) {
  const std::string name = kFingerNames[f];
  std::vector<ChainJoint> joints(4);
  joints[0].name = name + "_mcp_abduction";
  joints[0].X_parent_joint = Eigen::Translation3d(g.mcp_hand) *
                             Eigen::AngleAxisd(g.yaw_rad, Vec3::UnitZ()) *
                             Eigen::AngleAxisd(g.roll_rad, Vec3::UnitX());
  joints[0].axis = Vec3::UnitZ();
  joints[0].lower = -g.abduction_limit_rad;
  joints[0].upper = g.abduction_limit_rad;
  joints[0].child_link = name + "_mcp";
  joints[1].name = name + "_mcp_flexion";
  joints[1].axis = Vec3::UnitY();
  // A little hyperextension, as real MCP joints allow.
  joints[1].lower = -0.35;
  joints[1].upper = g.mcp_limit_rad;
  joints[1].child_link = name + "_proximal";
  joints[2].name = name + "_pip";
  joints[2].X_parent_joint = Iso3(Eigen::Translation3d(g.phalanx_m[0], 0.0, 0.0));
  joints[2].axis = Vec3::UnitY();
  joints[2].lower = 0.0;
  joints[2].upper = g.pip_limit_rad;
  joints[2].child_link = name + "_middle";
  joints[3].name = name + "_dip";
  joints[3].X_parent_joint = Iso3(Eigen::Translation3d(g.phalanx_m[1], 0.0, 0.0));
  joints[3].axis = Vec3::UnitY();
  joints[3].lower = 0.0;
  joints[3].upper = g.dip_limit_rad;
  joints[3].child_link = name + "_distal";
  return SerialChain("hand", std::move(joints),
                     Iso3(Eigen::Translation3d(g.phalanx_m[2], 0.0, 0.0)), name + "_tip");
}

double finite_or_zero(double v) {
  return std::isfinite(v) ? v : 0.0;
}

}  // namespace

std::array<FingerGeometry, kHandFingers> HandGeometry::default_fingers() {
  // Wrist at the origin. Lengths after adult hand anthropometry (phalanges of a ~19 cm hand).
  return {
      finger(Vec3(0.030, 0.035, -0.012), 0.8, 1.0, {0.045, 0.032, 0.027}, 0.009),   // thumb
      finger(Vec3(0.090, 0.025, 0.0), 0.05, 0.0, {0.045, 0.026, 0.022}, 0.008),     // index
      finger(Vec3(0.095, 0.002, 0.0), 0.0, 0.0, {0.050, 0.030, 0.023}, 0.008),      // middle
      finger(Vec3(0.090, -0.019, 0.0), -0.05, 0.0, {0.047, 0.028, 0.022}, 0.0075),  // ring
      finger(Vec3(0.080, -0.038, 0.0), -0.12, 0.0, {0.037, 0.021, 0.020}, 0.007),   // little
  };
}

HandModel::HandModel(HandGeometry geometry) : geometry_(std::move(geometry)) {
  if (!std::isfinite(geometry_.dip_per_pip) || geometry_.dip_per_pip < 0.0) {
    throw Error("hand", "DIP/PIP coupling ratio must be finite and >= 0, got " +
                            std::to_string(geometry_.dip_per_pip));
  }
  for (int f = 0; f < kHandFingers; ++f) {
    const FingerGeometry& g = geometry_.fingers[static_cast<std::size_t>(f)];
    const std::string where = std::string("hand finger '") + kFingerNames[f] + "'";
    for (const double l : g.phalanx_m) {
      if (!std::isfinite(l) || l <= 0.0) {
        throw Error(where, "phalanx lengths must be > 0 m, got " + std::to_string(l));
      }
    }
    if (!std::isfinite(g.tip_radius_m) || g.tip_radius_m < 0.0) {
      throw Error(where, "fingertip radius must be >= 0 m");
    }
    if (!g.mcp_hand.allFinite() || !std::isfinite(g.yaw_rad) || !std::isfinite(g.roll_rad)) {
      throw Error(where, "MCP position and orientation must be finite");
    }
    chains_.push_back(finger_chain(g, f));
  }
}

std::array<double, 4> HandModel::finger_joints(
    int f, const std::array<double, kGloveAnglesPerFinger>& angles_rad) const noexcept {
  const double pip = finite_or_zero(angles_rad[2]);
  std::array<double, 4> q{finite_or_zero(angles_rad[0]), finite_or_zero(angles_rad[1]), pip,
                          geometry_.dip_per_pip * pip};
  finger(f).clamp_to_limits(q);
  return q;
}

std::array<Vec3, kHandFingers> HandModel::fingertips_world(
    const GloveReading& reading) const noexcept {
  const Iso3 X_hand =
      reading.X_world_hand.matrix().allFinite() ? reading.X_world_hand : Iso3::Identity();
  std::array<Vec3, kHandFingers> tips;
  for (int f = 0; f < kHandFingers; ++f) {
    const auto q = finger_joints(f, reading.angles_rad[static_cast<std::size_t>(f)]);
    tips[static_cast<std::size_t>(f)] = X_hand * finger(f).forward(q).translation();
  }
  return tips;
}

Iso3 HandModel::finger_frames_world(int f, const GloveReading& reading,
                                    std::span<Iso3, 4> frames) const noexcept {
  const Iso3 X_hand =
      reading.X_world_hand.matrix().allFinite() ? reading.X_world_hand : Iso3::Identity();
  const auto q = finger_joints(f, reading.angles_rad[static_cast<std::size_t>(f)]);
  const Iso3 tip = finger(f).frames(q, frames);
  for (Iso3& X : frames) {
    X = X_hand * X;
  }
  return X_hand * tip;
}

GloveReading glove_reading(const Iso3& X_world_hand, std::span<const double> joint_rad) noexcept {
  GloveReading r;
  r.X_world_hand = X_world_hand;
  for (int f = 0; f < kHandFingers; ++f) {
    for (int k = 0; k < kGloveAnglesPerFinger; ++k) {
      const std::size_t i =
          static_cast<std::size_t>(f) * kGloveAnglesPerFinger + static_cast<std::size_t>(k);
      r.angles_rad[static_cast<std::size_t>(f)][static_cast<std::size_t>(k)] =
          i < joint_rad.size() ? joint_rad[i] : 0.0;
    }
  }
  return r;
}

}  // namespace hapsim
