// Stage 1: where the device puts each tool this step.
#include "hapsim/kinematics/hand_model.h"
#include "hapsim/world/world_model.h"
#include "hapsim/world/world_stages.h"
#include "hapsim/world/world_state.h"

#include <algorithm>
#include <array>

namespace hapsim::stage {

// haptic path
void place_tools(const WorldModel& model, WorldState& state, const DeviceInput& input,
                 double dt_s) noexcept {
  const WorldDescription& d = model.description();
  state.input_usable = input.healthy && input.p_world.allFinite() &&
                       input.q_world.coeffs().allFinite() && input.q_world.squaredNorm() > 0.5;
  if (!state.input_usable) {
    for (ToolRuntime& tool : state.tools) {
      tool.has_previous = false;  // no velocity spike when the input comes back
      for (PenaltySide& side : tool.penalty_side) {
        side = PenaltySide{};  // the tool may come back anywhere
      }
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
