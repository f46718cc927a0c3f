// The force a tool's device renders for it, as the session summary, the snapshots and the viewer
// report it: one rule for all of them.
#pragma once

#include "hapsim/core/device_io.h"
#include "hapsim/world/world_description.h"
#include "hapsim/world/world_state.h"

#include <cstddef>

namespace hapsim {

/// N: its finger actuator's force in `output` (the command after safety), or its share of the
/// tip force (`tip_scale` = |output's tip force| / |the world's tip force|). Another user's tool
/// (device > 0) is not in this device's command: the world's force on it, which that user's
/// device host renders. A tool a robot carries (`carried_by_rig`, TeleopRigDescription::
/// carried_tool) reaches the hand through the master's joints, not as a tip force: its own contact
/// force, before the master's scale. haptic path
[[nodiscard]] inline double tool_rendered_force_n(const ToolDescription& tool,
                                                  const ToolState& state,
                                                  const DeviceCommand& output, double tip_scale,
                                                  bool carried_by_rig = false) noexcept {
  if (tool.device != 0 || carried_by_rig) {
    return state.force_world_n.norm();
  }
  if (tool.finger >= 0 && tool.finger < output.finger_count) {
    return output.finger_force_n[static_cast<std::size_t>(tool.finger)];
  }
  return state.force_world_n.norm() * tip_scale;
}

}  // namespace hapsim
