// Stage 1: where the device puts each tool this step.
#include "hapsim/collision/sphere_tree.h"
#include "hapsim/kinematics/hand_model.h"
#include "hapsim/world/world_model.h"
#include "hapsim/world/world_stages.h"
#include "hapsim/world/world_state.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <utility>

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

// Bounds in the world of a box given in a body frame.
Box3 world_bounds(const Box3& box_body, const Iso3& X_world_body) noexcept {
  const Vec3 c = X_world_body * box_body.center();
  const Vec3 h = X_world_body.linear().cwiseAbs() * (0.5 * box_body.sizes());
  return Box3(c - h, c + h);
}

// Whether `tree`'s mesh, placed in `other`'s frame by X_other_mine, is deeper than
// RigState::kCollisionDepthM inside `other`. The tree is descended only where its spheres reach
// other's surface, the sphere most inside first, so a link through a table finds a leaf inside it
// (a few triangles, its sphere's centre on them) in about (levels × branching) queries; a leaf
// counts when its centre is that deep inside. A link hugging the surface without entering it
// would have every leaf along it tested: after kMaxQueries it is counted as touching (it is
// within a leaf's size of the surface all along). A link wholly inside a body, with no sphere
// reaching its surface, is not seen: it went in through the surface, and was counted then.
bool penetrates(const SphereTree& tree, const Iso3& X_other_mine,
                const ProximityQuery& other) noexcept {
  constexpr int kMaxQueries = 64;
  constexpr std::size_t kMaxSorted = 16;  // children ordered by depth (a tree has 4)
  const auto is_leaf = [&](std::uint32_t n) { return tree.node_children(n).empty(); };
  if (tree.node_count() == 0) {
    return false;
  }
  SurfacePoint sp;
  const Sphere root = tree.node_sphere(0);
  if (!other.contact_within(X_other_mine * root.center, root.radius, &sp)) {
    return false;
  }
  if (is_leaf(0)) {
    return sp.signed_distance < -RigState::kCollisionDepthM;
  }
  std::array<std::uint32_t, 128> stack{};
  std::size_t top = 0;
  stack[top++] = 0;
  int queries = 1;
  while (top > 0) {
    const std::uint32_t n = stack[--top];
    std::array<std::pair<double, std::uint32_t>, kMaxSorted> reaching{};
    std::size_t m = 0;
    for (const std::uint32_t child : tree.node_children(n)) {
      if (++queries > kMaxQueries) {
        return true;
      }
      const Sphere sphere = tree.node_sphere(child);
      if (!other.contact_within(X_other_mine * sphere.center, sphere.radius, &sp)) {
        continue;
      }
      if (is_leaf(child)) {
        if (sp.signed_distance < -RigState::kCollisionDepthM) {
          return true;
        }
      } else if (m < reaching.size()) {
        reaching[m++] = {sp.signed_distance, child};
      } else if (top < stack.size()) {
        stack[top++] = child;
      }
    }
    // The most inside last on the stack: visited next.
    std::sort(reaching.begin(), reaching.begin() + static_cast<std::ptrdiff_t>(m),
              [](const auto& a, const auto& b) { return a.first > b.first; });
    for (std::size_t i = 0; i < m && top < stack.size(); ++i) {
      stack[top++] = reaching[i].second;
    }
  }
  return false;
}

// The slave's collisions with what it cannot push back (the floor, the sheet): its bodies' bounds
// against theirs, then its sphere trees against their surfaces where the bounds meet.
void count_slave_collisions(const WorldModel& model, RigState& rig,
                            const WorldState& state) noexcept {
  TeleopStepResult& r = rig.result;
  r.slave_collisions = 0;
  r.slave_collision_bodies = 0;
  const std::vector<SegmentModel>& segs = model.segments();
  for (const RigState::Collider& c : rig.colliders) {
    const BodyState& body = state.bodies[c.body];
    const Box3 bounds = world_bounds(segs[c.flat].rest_bounds_body, body.X_world_body);
    for (const RigState::Obstacle& o : rig.obstacles) {
      if (!bounds.intersects(o.bounds_world)) {
        continue;
      }
      const SegmentModel& other = segs[o.flat];
      if (penetrates(*segs[c.flat].body_tree, state.bodies[o.body].X_body_world * body.X_world_body,
                     state.contact_query(other, o.flat))) {
        ++r.slave_collisions;
        for (const std::size_t b : {c.body, o.body}) {
          r.slave_collision_bodies |= b < 64 ? std::uint64_t{1} << b : 0;
        }
      }
    }
  }
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
  // One forward kinematics for the tool and the links (the same products as tip_pose()).
  r.slave_tool = rig.slave->chain().frames(rig.slave->q(), rig.frames);
  place_slave_bodies(d, rig, state, dt_s);
  place_pads(d, rig, state, dt_s);
  count_slave_collisions(model, rig, state);
}

// haptic path: a pose a tool can be placed from.
bool pose_usable(const DeviceInput& input) noexcept {
  return input.healthy && input.p_world.allFinite() && input.q_world.coeffs().allFinite() &&
         input.q_world.squaredNorm() > 0.5;
}

}  // namespace

// haptic path
double input_motion_time_s(double input_time_s, double input_time_previous_s,
                           double dt_s) noexcept {
  const double elapsed_s = input_time_s - input_time_previous_s;
  // Equal to the step within rounding (a local device read on the loop's clock, a script, a
  // replay of either): the step's own dt, so those velocities keep their bits.
  if (!std::isfinite(elapsed_s) || elapsed_s <= 0.0 || std::abs(elapsed_s - dt_s) <= 0.01 * dt_s ||
      elapsed_s > kMaxInputMotionTime_s) {
    return dt_s;
  }
  return elapsed_s;
}

// haptic path
void place_tools(const WorldModel& model, WorldState& state, const DeviceInput& input,
                 double dt_s) noexcept {
  const WorldDescription& d = model.description();
  if (state.rig) {
    place_rig(model, *state.rig, state, input, dt_s);
  }
  state.input_usable = pose_usable(input);
  if (model.hand() != nullptr) {
    // A glove's finger angles place the tools: a non-finite one makes the input unusable.
    const int n = std::clamp(input.joint_count, 0, kMaxDeviceJoints);
    for (int j = 0; j < n && state.input_usable; ++j) {
      state.input_usable = std::isfinite(input.joint_rad[static_cast<std::size_t>(j)]);
    }
  }
  std::array<Vec3, kHandFingers> tips{};
  const HandModel* hand = model.hand();
  if (hand != nullptr && state.input_usable) {
    Iso3 X_world_hand = Iso3::Identity();
    X_world_hand.linear() = input.q_world.normalized().toRotationMatrix();
    X_world_hand.translation() = input.p_world;
    state.hand = glove_reading(
        X_world_hand, {input.joint_rad.data(), static_cast<std::size_t>(std::clamp(
                                                   input.joint_count, 0, kMaxDeviceJoints))});
    tips = hand->fingertips_world(state.hand);
  }
  for (std::size_t t = 0; t < state.tools.size(); ++t) {
    ToolRuntime& tool = state.tools[t];
    const int device = d.tools[t].device;
    // Another user's tool takes that user's device's input (World::set_device_input).
    const DeviceInput& in = device >= 1 && device < kMaxWorldDevices
                                ? state.other_inputs[static_cast<std::size_t>(device - 1)]
                                : input;
    tool.input_usable = &in == &input ? state.input_usable : pose_usable(in);
    if (!state.tools_placed) {
      tool.placed = false;
    }
    if (!tool.input_usable) {
      tool.has_previous = false;  // no velocity spike when the input comes back
      for (PenaltySide& side : tool.penalty_side) {
        side = PenaltySide{};  // the tool may come back anywhere
      }
      std::fill(tool.pressing.begin(), tool.pressing.end(), std::uint8_t{0});
      std::fill(tool.stick_body.begin(), tool.stick_body.end(), StickPoint{});
      continue;
    }
    const Vec3 p_world =
        hand != nullptr && &in == &input
            ? tips[static_cast<std::size_t>(d.tools[t].finger)]
            : Vec3(in.p_world + in.q_world.normalized() * d.tools[t].offset_device);
    if (!tool.placed) {
      tool.proxy.reset(p_world);
      tool.proxy_surface_last_step = -1;
      tool.placed = true;
    }
    const double motion_s = input_motion_time_s(in.time_s, tool.input_time_previous_s, dt_s);
    tool.v_world = tool.has_previous && motion_s > 0.0
                       ? Vec3((p_world - tool.p_previous_world) / motion_s)
                       : Vec3::Zero();
    tool.moved_m = tool.has_previous ? (p_world - tool.p_previous_world).norm() : kInf;
    tool.p_previous_world = p_world;
    tool.input_time_previous_s = in.time_s;
    tool.has_previous = true;
    tool.p_world = p_world;
  }
  state.tools_placed = true;
}

}  // namespace hapsim::stage
