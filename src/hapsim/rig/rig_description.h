// A teleoperation rig's description (paper 000, architecture.md#controllers): the master arm, the
// slave chain, its gripper and the master→slave mapping, and which bodies of the world it drives
// (its pads and links) and reports on (the ball it picks, the sheet and floor it lays it on).
#pragma once

#include "hapsim/core/types.h"
#include "hapsim/deform/virtual_sheet.h"
#include "hapsim/kinematics/master_arm.h"
#include "hapsim/kinematics/serial_chain.h"
#include "hapsim/kinematics/slave_follower.h"
#include "hapsim/rig/ball_environment.h"
#include "hapsim/rig/parallel_gripper.h"
#include "hapsim/rig/rigid_ball.h"
#include "hapsim/rig/slave_shapes.h"

#include <array>
#include <cstddef>
#include <memory>
#include <vector>

namespace hapsim {

/// A teleoperation rig (paper 000): a 5-DOF master arm (the device: joint_rad[0..2] arm,
/// finger_rad[0..1] grasp) drives a slave robot with a parallel gripper through IK; the gripper
/// picks a rigid ball, which rests on a virtual sheet (or the floor) and imprints it, or carries a
/// probe tool that palpates tissue. Forces come back to the master as joint torques (the pads' and
/// the probe's reaction at the slave's tool, scaled, through Jᵀ) and finger torques (the grasp
/// force). The ball, the sheet and the floor are optional (kNoBody): a rig may only palpate.
struct TeleopRigDescription {
  MasterArmGeometry master;
  /// The slave arm (procedural Motoman or the GP7 URDF) and its start joints (dof() values;
  /// empty: all zero, clamped into the limits).
  std::shared_ptr<const SerialChain> slave;
  std::vector<double> slave_start_rad;
  TeleopMapping mapping;
  SlaveFollowerOptions follower;
  ParallelGripperParams gripper;
  RigidBallParams ball;
  Vec3 ball_start_world = Vec3(0.55, -0.25, 0.03);
  VirtualSheetOptions sheet;
  BallEnvironmentOptions environment;
  /// How the contact force at the slave's tool is scaled back onto the master's hand.
  double force_scale = 1.0;
  /// The rig's bodies in WorldDescription::bodies (rig_world() and add_rig() add the pads): the
  /// ball (dynamic), the sheet, the floor (each or kNoBody), the two gripper pads (kinematic; 0:
  /// the +y side).
  static constexpr std::size_t kNoBody = static_cast<std::size_t>(-1);
  std::size_t ball_body = kNoBody;
  std::size_t sheet_body = kNoBody;
  std::array<std::size_t, 2> pad_body{kNoBody, kNoBody};
  std::size_t floor_body = kNoBody;
  /// A body of the slave itself (kinematic: a link, the gripper's palm or stem), placed each step
  /// where its chain frame is (slave_shapes.h): X_world_body = X_world_frame · X_frame_body.
  struct SlaveBody {
    std::size_t body = kNoBody;
    /// −1: the base; i: joint i's frame after its motion; kToolFrame: the tool (flange).
    int frame = -1;
    Iso3 X_frame_body = Iso3::Identity();
  };
  /// The links in chain order, then the palm and stem (rig_world() adds them).
  std::vector<SlaveBody> slave_bodies;
  /// A tool of the world the slave carries instead of the hand (a probe at its gripper: the
  /// tele-palpation scene), or kNoTool. It is placed at the slave's tool (flange) frame, its own
  /// offset (ToolDescription::offset_device) in that frame; its contact force is felt at the
  /// master's hand like the pads'. Device 0's, with no finger.
  static constexpr std::size_t kNoTool = static_cast<std::size_t>(-1);
  std::size_t carried_tool = kNoTool;
};

/// The rig grasps a ball with its two pads (pick-and-place, not only palpation): their contacts
/// with it are what a served master feels of the grasp (rig/pad_models.h).
[[nodiscard]] inline bool grasps_ball(const TeleopRigDescription& d) noexcept {
  return d.ball_body != TeleopRigDescription::kNoBody &&
         d.pad_body[0] != TeleopRigDescription::kNoBody &&
         d.pad_body[1] != TeleopRigDescription::kNoBody;
}

}  // namespace hapsim
