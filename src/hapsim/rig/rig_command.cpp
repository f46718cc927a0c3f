// The rig's command (rig_controller.h): the pads' reaction at the slave's tool back to the
// master's joints through its Jᵀ, the grasp to its fingers.
#include "hapsim/rig/rig_controller.h"
#include "hapsim/world/world_model.h"
#include "hapsim/world/world_state.h"

#include <algorithm>
#include <cmath>
#include <limits>

namespace hapsim {

namespace {

// The pads' squeeze on the ball, read off their contacts with it (body-contact stage): each pad's
// normal force and what the pads push on the ball together. What the master's fingers feel.
// haptic path
void pad_forces(const TeleopRigDescription& d, const WorldState& state, GripperReport& g) noexcept {
  g.pad_force_n = {0.0, 0.0};
  g.force_on_ball_world_n.setZero();
  if (d.ball_body == TeleopRigDescription::kNoBody) {
    return;
  }
  for (std::size_t k = 0; k < state.body_contact_count; ++k) {
    const BodyContact& c = state.body_contacts[k];
    for (std::size_t i = 0; i < 2; ++i) {
      if (c.body == BodyIndex{d.ball_body} && c.other_body == BodyIndex{d.pad_body[i]}) {
        g.pad_force_n[i] = std::max(0.0, c.force_world_n.dot(c.normal_world));
        g.force_on_ball_world_n += c.force_world_n;
      }
    }
  }
}

}  // namespace

// What the slave's joints hold against the carried tool's force F at its centre: the wrench
// [F; (p_tool − p_flange) × F] at the flange through the slave's Jᵀ. haptic path
void slave_joint_torques(const RigState& rig, const Vec3& p_tool_world, const Vec3& force_world_n,
                         TeleopStepResult& r) noexcept {
  r.slave_joint_torque_nm.fill(0.0);
  const ChainJacobian J = rig.slave->chain().jacobian(rig.slave->q());
  Eigen::Matrix<double, 6, 1> wrench;
  wrench.head<3>() = force_world_n;
  wrench.tail<3>() = (p_tool_world - r.slave_tool.translation()).cross(force_world_n);
  const ChainVector tau = J.transpose() * wrench;
  for (Eigen::Index i = 0; i < tau.size(); ++i) {
    r.slave_joint_torque_nm[static_cast<std::size_t>(i)] = tau(i);
  }
}

// The rig's forces back to the master: the reaction at the slave's tool (the pads', and the
// palm's and stem's when the ball presses them: the gripper's parts past the wrist; the carried
// tool's contact force), scaled into the master's frame and turned into joint torques through the
// master's Jᵀ; the grasp force on both fingers. The links' contacts are not felt: they are the
// arm's, not the hand's.
// haptic path
void RigState::command(const WorldModel& /*model*/, const WorldState& state,
                       DeviceCommand& command) noexcept {
  RigState& rig = *this;
  TeleopStepResult& r = rig.result;
  pad_forces(*description, state, r.gripper);
  r.command = DeviceCommand{};
  command = r.command;  // the master has no probe tools: the rig's command is all it gets
  if (!rig.input_usable) {
    return;
  }
  const TeleopRigDescription& d = *description;
  // What the ball pushes on the pads (held by friction: its weight and whatever the sheet or
  // the floor push on it, carried through the grasp).
  Vec3 at_tool = -r.gripper.force_on_ball_world_n;
  for (const TeleopRigDescription::SlaveBody& s : d.slave_bodies) {
    if (s.frame == kToolFrame) {
      at_tool += state.bodies[s.body].force_world_n;
    }
  }
  if (d.carried_tool != TeleopRigDescription::kNoTool) {
    const ToolState& tool = state.tool_states[d.carried_tool];
    at_tool += tool.force_world_n;
    slave_joint_torques(rig, tool.p_world, tool.force_world_n, r);
  }
  r.tool_force_world_n = at_tool;
  controller->master_command(r.master_arm_rad, at_tool, r.gripper.grasp_force_n(), r.command);
  command = r.command;
}

// haptic path
void RigController::master_command(const std::array<double, 3>& arm_rad,
                                   const Vec3& force_at_slave_tool_world_n, double grasp_force_n,
                                   DeviceCommand& command) const noexcept {
  const TeleopRigDescription& d = description_;
  const Vec3 at_master =
      d.mapping.X_slave_master.linear().transpose() * force_at_slave_tool_world_n * d.force_scale;
  const MasterTorques t = master_.torques(arm_rad, at_master, grasp_force_n);
  for (std::size_t i = 0; i < 3; ++i) {
    command.joint_torque_nm[i] = t.arm_n_m[i];
  }
  command.joint_torque_nm[3] = t.fingers_n_m[0];
  command.joint_torque_nm[4] = t.fingers_n_m[1];
  command.joint_count = 5;
  command.finger_force_n[0] = std::isfinite(grasp_force_n) ? grasp_force_n : 0.0;
  command.finger_force_n[1] = command.finger_force_n[0];
  command.finger_count = 2;
  for (double& torque : command.joint_torque_nm) {
    torque = std::isfinite(torque) ? torque : 0.0;
  }
}

// haptic path
Vec3 RigController::flange_point_target_world(const DeviceInput& input,
                                              const Vec3& p_flange_m) const noexcept {
  const std::array<double, 3> arm{input.joint_rad[0], input.joint_rad[1], input.joint_rad[2]};
  if (input.joint_count < 3 || !std::isfinite(arm[0]) || !std::isfinite(arm[1]) ||
      !std::isfinite(arm[2])) {
    return Vec3::Constant(std::numeric_limits<double>::quiet_NaN());
  }
  const Iso3 hand = master_.hand_pose(arm);
  return slave_target(description_.mapping, hand.translation(), arm[0]) * p_flange_m;
}

// haptic path
Vec3 RigController::pad_centre_target_world(const DeviceInput& input,
                                            std::size_t pad) const noexcept {
  const double fingers[2] = {input.finger_rad[0], input.finger_rad[1]};
  if (pad > 1 || input.finger_count < 2 || !std::isfinite(fingers[0]) ||
      !std::isfinite(fingers[1])) {
    return Vec3::Constant(std::numeric_limits<double>::quiet_NaN());
  }
  // Where place_pads (rig_place.cpp) puts it about the tool, at the opening the grip asks for.
  const double width =
      std::max(slave_width_for(master_.grip_opening_m({fingers[0], fingers[1]})), 0.0);
  return flange_point_target_world(input, pad_centre_tool(description_.gripper, width, pad));
}

}  // namespace hapsim
