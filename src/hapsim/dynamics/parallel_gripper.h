// The slave's two-finger parallel gripper and the grasp (000 §1, architecture.md#kinematics): two box pads that close
// along the tool's y axis below the flange (tool z points out of the flange). A pad touching the
// ball pushes it with a contact spring (and friction); the ball is *held* when both pads press it
// from opposite sides hard enough that friction carries its weight — μ·(N₁ + N₂) ≥ safety·m·g —
// and then moves with the gripper; it is released when either pad lets go. The pads stop where
// their force reaches the gripper's limit, as a force-limited gripper closing on an object does.
#pragma once

#include "hapsim/dynamics/contact_spring.h"
#include "hapsim/dynamics/rigid_ball.h"

#include <array>

namespace hapsim {

struct ParallelGripperParams {
  /// Pad half extents in the tool frame (x across, y thickness, z along the fingers), metres.
  Vec3 pad_half_m = Vec3(0.012, 0.004, 0.02);
  /// Pad centres lie this far out of the flange along tool z.
  double pad_depth_m = 0.07;
  ContactSpring pad_contact{.stiffness_n_per_m = 5000.0,
                            .damping_n_s_per_m = 10.0,
                            .friction = 0.8,
                            .friction_stiffness_n_per_m = 5000.0,
                            .friction_damping_n_s_per_m = 10.0};
  /// The most each pad pushes (the gripper motor's limit), newtons.
  double max_force_n = 20.0;
  /// Friction must carry this multiple of the ball's weight to call it held.
  double safety_factor = 1.5;
};

struct GripperReport {
  /// Normal force of each pad on the ball, newtons (≥ 0).
  std::array<double, 2> pad_force_n{};
  /// Total force of the pads on the ball, world frame (zero while held: the grasp carries it).
  Vec3 force_on_ball_world_n = Vec3::Zero();
  /// Pad opening actually reached (≥ the command when the pads press the ball at their limit).
  double width_m = 0.0;
  bool held = false;
  /// This cycle the ball was grasped / let go.
  bool grasped_now = false;
  bool released_now = false;
  /// (N₁ + N₂) / 2: what the master's fingers feel.
  [[nodiscard]] double grasp_force_n() const { return 0.5 * (pad_force_n[0] + pad_force_n[1]); }
};

class ParallelGripper {
 public:
  /// Throws hapsim::Error on non-positive pad sizes, stiffness or force limit.
  explicit ParallelGripper(ParallelGripperParams params = {});

  /// One cycle: the pads at `X_world_tool` opened to `commanded_width_m` (stopped earlier by the
  /// force limit) touch the ball; grasp or release; a held ball is moved with the tool. The
  /// returned force is for the ball's free step (zero while held). haptic path
  GripperReport step(const Iso3& X_world_tool, double commanded_width_m, RigidBall& ball,
                     double dt_s) noexcept;

  [[nodiscard]] const ParallelGripperParams& params() const { return params_; }
  /// Pad centre i (0: +y side, 1: −y side) in the world for the tool pose and opening.
  [[nodiscard]] Vec3 pad_center_world(const Iso3& X_world_tool, double width_m, int pad) const;

 private:
  ParallelGripperParams params_;
  std::array<FrictionAnchor, 2> anchors_{};
  std::array<Vec3, 2> previous_pad_world_{Vec3::Zero(), Vec3::Zero()};
  bool has_previous_ = false;
  bool held_ = false;
  Vec3 p_tool_ball_ = Vec3::Zero();
};

}  // namespace hapsim
