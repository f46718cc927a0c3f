// The virtual hand of the knee paper (§3.1): five fingers of 4 DOF each — MCP abduction, MCP
// flexion, PIP and DIP — with the DIP angle coupled to the PIP (DIP = ⅔·PIP by default, as a
// DataGlove measures only MCP and PIP), placed in the world by the tracker's pose. Each finger is
// a SerialChain, so fingertips come from chained homogeneous transforms like the arms' tips.
//
// Hand frame (a right hand, palm down): x along the middle finger, y towards the thumb, z out of
// the back of the hand. Positive flexion curls a finger towards the palm (a rotation about the
// finger's y axis, which turns x towards −z); positive abduction spreads it towards +y.
#pragma once

#include "hapsim/kinematics/serial_chain.h"

#include <array>
#include <span>

namespace hapsim {

inline constexpr int kHandFingers = 5;  // thumb, index, middle, ring, little
/// Glove angles per finger: MCP abduction, MCP flexion, PIP flexion.
inline constexpr int kGloveAnglesPerFinger = 3;

struct FingerGeometry {
  /// MCP joint in the hand frame, metres.
  Vec3 mcp_hand = Vec3::Zero();
  /// The finger's rest frame at the MCP (its x along the straight finger), as rotations about
  /// the hand's z then x (radians): a thumb points sideways and rolls towards the palm.
  double yaw_rad = 0.0;
  double roll_rad = 0.0;
  /// Proximal, middle and distal phalanx lengths, metres (to the fingertip sphere's centre).
  std::array<double, 3> phalanx_m{0.045, 0.025, 0.02};
  /// Fingertip sphere radius, metres.
  double tip_radius_m = 0.008;
  /// Joint limits, radians: abduction ±, flexion of MCP / PIP / DIP from 0 (straight) up.
  double abduction_limit_rad = 0.35;
  double mcp_limit_rad = 1.57;
  double pip_limit_rad = 1.92;
  double dip_limit_rad = 1.40;
};

struct HandGeometry {
  /// An adult hand's proportions (about 19 cm long), thumb first.
  std::array<FingerGeometry, kHandFingers> fingers = default_fingers();
  /// DIP = ratio · PIP.
  double dip_per_pip = 2.0 / 3.0;

  static std::array<FingerGeometry, kHandFingers> default_fingers();
};

/// What a glove gives: the tracker's pose and three angles per finger (radians).
struct GloveReading {
  Iso3 X_world_hand = Iso3::Identity();
  /// [finger][abduction, mcp, pip].
  std::array<std::array<double, kGloveAnglesPerFinger>, kHandFingers> angles_rad{};
};

class HandModel {
 public:
  /// Throws hapsim::Error naming the finger for non-positive or non-finite lengths or radii.
  explicit HandModel(HandGeometry geometry = {});

  [[nodiscard]] const HandGeometry& geometry() const { return geometry_; }
  /// Finger f as a 4-joint chain (abduction, MCP, PIP, DIP) from the hand frame to its tip.
  [[nodiscard]] const SerialChain& finger(int f) const {
    return chains_[static_cast<std::size_t>(f)];
  }

  /// The four joint values of finger f for its glove angles: limits applied, DIP coupled.
  /// haptic path
  [[nodiscard]] std::array<double, 4> finger_joints(
      int f, const std::array<double, kGloveAnglesPerFinger>& angles_rad) const noexcept;

  /// Fingertip sphere centres in the world frame. Non-finite angles count as 0 (straight),
  /// a non-finite tracker pose gives the hand's rest at the origin. haptic path
  [[nodiscard]] std::array<Vec3, kHandFingers> fingertips_world(
      const GloveReading& reading) const noexcept;

  /// Every joint frame of finger f in the world (4 frames) and its tip, for display. haptic path
  Iso3 finger_frames_world(int f, const GloveReading& reading,
                           std::span<Iso3, 4> frames) const noexcept;

 private:
  HandGeometry geometry_;
  std::vector<SerialChain> chains_;
};

/// Glove readings from a device input: the pose, and joint_rad[3·f + k] as finger f's angle k
/// (the simulated glove plays a trajectory file with columns j0..j14). Missing joints read 0.
[[nodiscard]] GloveReading glove_reading(const Iso3& X_world_hand,
                                         std::span<const double> joint_rad) noexcept;

}  // namespace hapsim
