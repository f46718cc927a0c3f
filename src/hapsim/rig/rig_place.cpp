// The rig's place stage (rig_controller.h): the slave follows the master's hand through IK, and
// its links, palm, stem and gripper pads (kinematic bodies of the world) are put at its joint
// frames with the velocities their motion since the last step gives them.
#include "hapsim/rig/rig_controller.h"
#include "hapsim/world/world_model.h"
#include "hapsim/world/world_state.h"

#include <algorithm>
#include <array>
#include <cmath>

namespace hapsim {

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
  const Vec3& half = g.pad_half_m;
  double width = std::max(rig.slave->gripper_width_m(), 0.0);
  const Vec3 c = d.ball_body != TeleopRigDescription::kNoBody
                     ? Vec3(X_tool_world * state.bodies[d.ball_body].X_world_body.translation())
                     : Vec3::Constant(kInf);
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
    BodyState& pad = state.bodies[d.pad_body[i]];
    pad.X_world_body = X_world_tool * Eigen::Translation3d(pad_centre_tool(g, width, i));
    pad.X_body_world = pad.X_world_body.inverse();
    const Vec3 p = pad.X_world_body.translation();
    pad.v_world = rig.has_pad_previous && dt_s > 0.0 ? Vec3((p - rig.pad_previous_world[i]) / dt_s)
                                                     : Vec3::Zero();
    pad.w_world = w_world;
    rig.pad_previous_world[i] = p;
  }
  rig.has_pad_previous = true;
}

// Velocity of a rigidly moving frame's origin and its angular velocity, from its pose last step
// (zero without one).
void frame_velocity(const Iso3& X_now, const Iso3& X_before, bool has_before, double dt_s,
                    Vec3& v_world, Vec3& w_world) noexcept {
  v_world.setZero();
  w_world.setZero();
  if (!has_before || !(dt_s > 0.0)) {
    return;
  }
  v_world = (X_now.translation() - X_before.translation()) / dt_s;
  // The turn R = exp(θ k) since last step from its skew part (2 sin θ k) and trace (1 + 2 cos θ):
  // exact, and cheaper than an angle-axis decomposition per body.
  const Mat3 R = X_now.linear() * X_before.linear().transpose();
  const Vec3 two_sin_k(R(2, 1) - R(1, 2), R(0, 2) - R(2, 0), R(1, 0) - R(0, 1));
  const double sin_angle = 0.5 * two_sin_k.norm();
  const double angle = std::atan2(sin_angle, 0.5 * (R.trace() - 1.0));
  w_world = sin_angle > 1e-12 ? Vec3(two_sin_k * (0.5 * angle / (sin_angle * dt_s)))
                              : Vec3(0.5 * two_sin_k / dt_s);
}

// The slave's links, palm and stem (kinematic bodies) at this step's joint frames: the chain's
// forward kinematics, as the pads are placed from its tool. Moving, they push the ball through
// the body-contact stage like the pads do.
void place_slave_bodies(const TeleopRigDescription& d, RigState& rig, WorldState& state,
                        double dt_s) noexcept {
  for (std::size_t k = 0; k < d.slave_bodies.size(); ++k) {
    const TeleopRigDescription::SlaveBody& s = d.slave_bodies[k];
    const Iso3& X_world_frame = s.frame == kToolFrame ? rig.result.slave_tool
                                : s.frame < 0         ? Iso3::Identity()
                                              : rig.frames[static_cast<std::size_t>(s.frame)];
    BodyState& body = state.bodies[s.body];
    body.X_world_body = X_world_frame * s.X_frame_body;
    body.X_body_world = body.X_world_body.inverse();
    frame_velocity(body.X_world_body, rig.slave_body_previous[k], rig.has_pad_previous, dt_s,
                   body.v_world, body.w_world);
    rig.slave_body_previous[k] = body.X_world_body;
  }
}

// The rig's tool is the slave's gripper: the master's hand pose, scaled into the slave's frame,
// is the slave's IK target; the master's grip opening is the gripper's. On an unusable input the
// slave brakes to rest at its acceleration limit and stands, its gripper as it was.
}  // namespace

// haptic path
void RigState::place(const WorldModel& model, WorldState& state, const DeviceInput& input,
                     DeviceInput& tool_input, double dt_s) noexcept {
  RigState& rig = *this;
  const TeleopRigDescription& d = *description;
  TeleopStepResult& r = rig.result;
  const std::array<double, 3> arm{input.joint_rad[0], input.joint_rad[1], input.joint_rad[2]};
  const std::array<double, 2> fingers{input.finger_rad[0], input.finger_rad[1]};
  // A master gives three arm joints and two fingers: fewer is not a master's reading.
  rig.input_usable = input.healthy && input.joint_count >= 3 && input.finger_count >= 2;
  for (const double v : {arm[0], arm[1], arm[2], fingers[0], fingers[1]}) {
    rig.input_usable = rig.input_usable && std::isfinite(v);
  }
  if (rig.input_usable) {
    r.master_arm_rad = arm;
    r.master_finger_rad = fingers;
    r.master_hand = controller->master().hand_pose(arm);
    const Iso3 target = slave_target(d.mapping, r.master_hand.translation(), arm[0]);
    const double width_command =
        controller->slave_width_for(controller->master().grip_opening_m(fingers));
    r.slave = rig.slave->step(target, width_command, dt_s);
  } else {
    r.slave = rig.slave->stop(dt_s);
  }
  // One forward kinematics for the tool and the links (the same products as tip_pose()).
  r.slave_tool = rig.slave->chain().frames(rig.slave->q(), rig.frames);
  place_slave_bodies(d, rig, state, dt_s);
  place_pads(d, rig, state, dt_s);
  count_slave_collisions(model, rig, state);
  if (d.carried_tool != TeleopRigDescription::kNoTool) {
    // The carried tool follows the slave's flange, not the master's hand: its input is the
    // flange's pose (the tool's own offset is in that frame), usable when the master's is.
    tool_input.p_world = r.slave_tool.translation();
    tool_input.q_world = Quat(r.slave_tool.linear());
    tool_input.healthy = rig.input_usable;
  }
}

}  // namespace hapsim
