// Stage 1: where the device puts each tool this step.
#include "hapsim/kinematics/hand_model.h"
#include "hapsim/world/world_model.h"
#include "hapsim/world/world_stages.h"
#include "hapsim/world/world_state.h"

#include <algorithm>
#include <array>
#include <cmath>

namespace hapsim::stage {

namespace {

// The gripper's pads at the slave's tool (000 §1): two boxes that close symmetrically along the
// tool's y axis, pad_depth_m out along its z, to the slave's gripper opening — stopped where they
// would press the ball at the gripper's force limit, as a force-limited gripper closing on an
// object does (the pad material's force cap holds the rest). Kinematic bodies: the rig moves them.
void place_pads(const TeleopRigDescription& d, RigState& rig, WorldState& state,
                double dt_s) noexcept {
  const ParallelGripperParams& g = d.gripper;
  const Iso3& X_world_tool = rig.result.slave_tool;
  const Iso3 X_tool_world = X_world_tool.inverse();
  const Vec3 c = X_tool_world * state.bodies[d.ball_body].X_world_body.translation();
  const Vec3& half = g.pad_half_m;
  double width = std::max(rig.slave->gripper_width_m(), 0.0);
  if (std::abs(c.x()) <= half.x() && std::abs(c.z() - g.pad_depth_m) <= half.z()) {
    const double pen_max = g.max_force_n / g.pad_contact.stiffness_n_per_m;
    width = std::max(width, 2.0 * (d.ball.radius_m - pen_max + std::abs(c.y())));
  }
  rig.result.gripper.width_m = width;
  // The pads turn with the tool: ω from this step's rotation of it (none on the first step).
  Vec3 w_world = Vec3::Zero();
  if (rig.has_pad_previous && dt_s > 0.0) {
    const Eigen::AngleAxisd turn(X_world_tool.linear() * rig.tool_previous_R.transpose());
    w_world = turn.axis() * (turn.angle() / dt_s);
  }
  rig.tool_previous_R = X_world_tool.linear();
  for (std::size_t i = 0; i < 2; ++i) {
    const double side = i == 0 ? 1.0 : -1.0;
    BodyState& pad = state.bodies[d.pad_body[i]];
    pad.X_world_body =
        X_world_tool * Eigen::Translation3d(0.0, side * (0.5 * width + half.y()), g.pad_depth_m);
    pad.X_body_world = pad.X_world_body.inverse();
    const Vec3 p = pad.X_world_body.translation();
    pad.v_world = rig.has_pad_previous && dt_s > 0.0 ? Vec3((p - rig.pad_previous_world[i]) / dt_s)
                                                     : Vec3::Zero();
    pad.w_world = w_world;
    rig.pad_previous_world[i] = p;
  }
  rig.has_pad_previous = true;
}

// The rig's tool is the slave's gripper: the master's hand pose, scaled into the slave's frame,
// is the slave's IK target; the master's grip opening is the gripper's. On an unusable input the
// slave holds where it is.
void place_rig(const WorldModel& model, RigState& rig, WorldState& state, const DeviceInput& input,
               double dt_s) noexcept {
  const TeleopRigDescription& d = *model.description().teleop;
  TeleopStepResult& r = rig.result;
  const std::array<double, 3> arm{input.joint_rad[0], input.joint_rad[1], input.joint_rad[2]};
  const std::array<double, 2> fingers{input.finger_rad[0], input.finger_rad[1]};
  // A master gives three arm joints and two fingers: fewer is not a master's reading.
  rig.input_usable = input.healthy && input.joint_count >= 3 && input.finger_count >= 2;
  for (const double v : {arm[0], arm[1], arm[2], fingers[0], fingers[1]}) {
    rig.input_usable = rig.input_usable && std::isfinite(v);
  }
  double width_command = rig.slave->gripper_width_m();
  if (rig.input_usable) {
    r.master_arm_rad = arm;
    r.master_finger_rad = fingers;
    r.master_hand = model.master()->hand_pose(arm);
    const Iso3 target = slave_target(d.mapping, r.master_hand.translation(), arm[0]);
    width_command = model.slave_width_for(model.master()->grip_opening_m(fingers));
    r.slave = rig.slave->step(target, width_command, dt_s);
  } else {
    r.slave = rig.slave->step(rig.slave->tip_pose(), width_command, dt_s);
  }
  r.slave_tool = rig.slave->tip_pose();
  place_pads(d, rig, state, dt_s);
}

}  // namespace

// haptic path
void place_tools(const WorldModel& model, WorldState& state, const DeviceInput& input,
                 double dt_s) noexcept {
  const WorldDescription& d = model.description();
  if (state.rig) {
    place_rig(model, *state.rig, state, input, dt_s);
  }
  state.input_usable = input.healthy && input.p_world.allFinite() &&
                       input.q_world.coeffs().allFinite() && input.q_world.squaredNorm() > 0.5;
  if (model.hand() != nullptr) {
    // A glove's finger angles place the tools: a non-finite one makes the input unusable.
    const int n = std::clamp(input.joint_count, 0, kMaxDeviceJoints);
    for (int j = 0; j < n && state.input_usable; ++j) {
      state.input_usable = std::isfinite(input.joint_rad[static_cast<std::size_t>(j)]);
    }
  }
  if (!state.input_usable) {
    for (ToolRuntime& tool : state.tools) {
      tool.has_previous = false;  // no velocity spike when the input comes back
      for (PenaltySide& side : tool.penalty_side) {
        side = PenaltySide{};  // the tool may come back anywhere
      }
      std::fill(tool.pressing.begin(), tool.pressing.end(), std::uint8_t{0});
      std::fill(tool.stick_body.begin(), tool.stick_body.end(), StickPoint{});
    }
    return;
  }
  const Quat q = input.q_world.normalized();
  std::array<Vec3, kHandFingers> tips{};
  if (const HandModel* hand = model.hand()) {
    Iso3 X_world_hand = Iso3::Identity();
    X_world_hand.linear() = q.toRotationMatrix();
    X_world_hand.translation() = input.p_world;
    tips = hand->fingertips_world(glove_reading(
        X_world_hand, {input.joint_rad.data(), static_cast<std::size_t>(std::clamp(
                                                   input.joint_count, 0, kMaxDeviceJoints))}));
  }
  for (std::size_t t = 0; t < state.tools.size(); ++t) {
    ToolRuntime& tool = state.tools[t];
    const Vec3 p_world = model.hand() != nullptr
                             ? tips[static_cast<std::size_t>(d.tools[t].finger)]
                             : Vec3(input.p_world + q * d.tools[t].offset_device);
    if (!state.tools_placed) {
      tool.proxy.reset(p_world);
    }
    tool.v_world = tool.has_previous && dt_s > 0.0 ? Vec3((p_world - tool.p_previous_world) / dt_s)
                                                   : Vec3::Zero();
    tool.moved_m = tool.has_previous ? (p_world - tool.p_previous_world).norm() : kInf;
    tool.p_previous_world = p_world;
    tool.has_previous = true;
    tool.p_world = p_world;
  }
  state.tools_placed = true;
}

}  // namespace hapsim::stage
