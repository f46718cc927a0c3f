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

// haptic path
void safety(const WorldModel& model, WorldState& state) noexcept {
  state.command = DeviceCommand{};
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
  if (state.controller) {
    // A controller that drives the device another way (a master arm's joint torques) writes
    // its own command.
    state.controller->command(model, state, state.command);
  }
}

}  // namespace hapsim::stage
