// Stage 6: what leaves the world is finite. A tool whose force is not finite renders nothing; the
// device command is assembled from the tools (a finger tool drives its finger's actuator, the
// largest force among its tools; the others add up at the tip). The device's own limits (its
// rated force, the stall ramp) are applied after the world, by the runtime's safety layer
// (device/force_safety.h), which knows the device.
#include "hapsim/world/world_model.h"
#include "hapsim/world/world_stages.h"
#include "hapsim/world/world_state.h"

#include <algorithm>
#include <cmath>

namespace hapsim::stage {

namespace {

// The rig's forces back to the master: the reaction at the slave's tool (the pads', and the
// palm's and stem's when the ball presses them: the gripper's parts past the wrist), scaled into
// the master's frame and turned into joint torques through the master's Jᵀ; the grasp force on
// both fingers. The links' contacts are not felt: they are the arm's, not the hand's.
void rig_command(const WorldModel& model, const WorldState& state, RigState& rig) noexcept {
  TeleopStepResult& r = rig.result;
  r.command = DeviceCommand{};
  if (!rig.input_usable) {
    return;
  }
  const TeleopRigDescription& d = *model.description().teleop;
  // What the ball pushes on the pads (held by friction: its weight and whatever the sheet or
  // the floor push on it, carried through the grasp).
  Vec3 at_tool = -r.gripper.force_on_ball_world_n;
  for (const TeleopRigDescription::SlaveBody& s : d.slave_bodies) {
    if (s.frame == kToolFrame) {
      at_tool += state.bodies[s.body].force_world_n;
    }
  }
  const Vec3 at_master = d.mapping.X_slave_master.linear().transpose() * at_tool * d.force_scale;
  const MasterTorques t =
      model.master()->torques(r.master_arm_rad, at_master, r.gripper.grasp_force_n());
  for (std::size_t i = 0; i < 3; ++i) {
    r.command.joint_torque_nm[i] = t.arm_n_m[i];
  }
  r.command.joint_torque_nm[3] = t.fingers_n_m[0];
  r.command.joint_torque_nm[4] = t.fingers_n_m[1];
  r.command.joint_count = 5;
  const double grasp = r.gripper.grasp_force_n();
  r.command.finger_force_n[0] = std::isfinite(grasp) ? grasp : 0.0;
  r.command.finger_force_n[1] = r.command.finger_force_n[0];
  r.command.finger_count = 2;
  for (double& torque : r.command.joint_torque_nm) {
    torque = std::isfinite(torque) ? torque : 0.0;
  }
}

}  // namespace

// haptic path
void safety(const WorldModel& model, WorldState& state) noexcept {
  state.command = DeviceCommand{};
  if (state.rig) {
    // A rig's master gets the rig's torques and grasp (its scenes have no probe tools).
    rig_command(model, state, *state.rig);
    state.command = state.rig->result.command;
  }
  const WorldDescription& d = model.description();
  for (std::size_t t = 0; t < state.tool_states.size(); ++t) {
    ToolState& out = state.tool_states[t];
    // A tool whose device's input is unusable holds with no force (zero, never NaN).
    const bool usable = t < state.tools.size() && state.tools[t].input_usable;
    out.present = d.tools[t].device == 0 || (usable && state.tools[t].placed);
    if (!usable) {
      out.contact_count = 0;
    }
    if (!usable || !out.force_world_n.allFinite()) {
      out.force_world_n.setZero();
    }
    if (d.tools[t].device != 0) {
      continue;  // another user's: rendered by that user's device host from its local models
    }
    const int finger = d.tools[t].finger;
    if (finger >= 0) {
      auto& f = state.command.finger_force_n[static_cast<std::size_t>(finger)];
      f = std::max(f, out.force_world_n.norm());
      state.command.finger_count = std::max(state.command.finger_count, finger + 1);
    } else {
      state.command.force_world_n += out.force_world_n;
    }
  }
}

}  // namespace hapsim::stage
