// Stage 1: where the device puts each tool this step.
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
void place_tools(const WorldModel& model, WorldState& state, const DeviceInput& device_input,
                 double dt_s) noexcept {
  const WorldDescription& d = model.description();
  // A controller moves the bodies it drives, and may put device 0's tools where its own
  // mechanism holds them (a robot's tool), before the tools are placed.
  DeviceInput controlled;
  const DeviceInput* own_input = &device_input;
  if (state.controller) {
    controlled = device_input;
    state.controller->place(model, state, device_input, controlled, dt_s);
    own_input = &controlled;
  }
  const DeviceInput& input = *own_input;
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
