// The slave's two-finger parallel gripper (000 §1, architecture.md#kinematics): two box pads that
// close along the tool's y axis below the flange (tool z points out of the flange), stopping where
// their force reaches the gripper's limit. rig_world() makes the pads kinematic world bodies; the
// rig's stages move them with the slave and read the grasp off their contacts with the ball: held
// when both pads press it from opposite sides hard enough that friction carries its weight,
// μ·(N₁ + N₂) ≥ safety·m·g (a report: the ball is held by friction, nothing attaches it).
#pragma once

#include "hapsim/core/types.h"
#include "hapsim/rig/contact_spring.h"

#include <array>
#include <cstddef>

namespace hapsim {

struct ParallelGripperParams {
  /// Pad half extents in the tool frame (x across, y thickness, z along the fingers), metres.
  Vec3 pad_half_m = Vec3(0.012, 0.004, 0.02);
  /// Pad centres lie this far out of the flange along tool z.
  double pad_depth_m = 0.07;
  ContactSpring pad_contact{
      .stiffness_n_per_m = 5000.0, .damping_n_s_per_m = 10.0, .friction = 0.8};
  /// The most each pad pushes (the gripper motor's limit), newtons.
  double max_force_n = 20.0;
  /// Friction must carry this multiple of the ball's weight to call it held.
  double safety_factor = 1.5;
};

/// Where pad `pad` (0: the +y side) is centred in the tool frame at the opening `width_m`: along
/// the tool's y, half the opening and half its own thickness out, pad_depth_m along its z.
[[nodiscard]] inline Vec3 pad_centre_tool(const ParallelGripperParams& g, double width_m,
                                          std::size_t pad) noexcept {
  const double side = pad == 0 ? 1.0 : -1.0;
  return {0.0, side * (0.5 * width_m + g.pad_half_m.y()), g.pad_depth_m};
}

struct GripperReport {
  /// Normal force of each pad on the ball, newtons (≥ 0).
  std::array<double, 2> pad_force_n{};
  /// Total force of the pads on the ball, world frame.
  Vec3 force_on_ball_world_n = Vec3::Zero();
  /// Pad opening actually reached (≥ the command when the pads press the ball at their limit).
  double width_m = 0.0;
  bool held = false;
  /// This step the grasp began / ended. A grasp ends once either pad has been off the ball for
  /// kReleaseAfterS (a pad a jerk of the slave lifts off for a step or two lets nothing go), and
  /// `released_at_s` is when that began.
  bool grasped_now = false;
  bool released_now = false;
  double released_at_s = -1.0;
  static constexpr double kReleaseAfterS = 0.02;
  /// (N₁ + N₂) / 2: what the master's fingers feel.
  [[nodiscard]] double grasp_force_n() const { return 0.5 * (pad_force_n[0] + pad_force_n[1]); }
};

}  // namespace hapsim
