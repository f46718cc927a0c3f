// The full scale of the force displays (the column graph, its plots, the tools' colour): what the
// scene can push with, within what the device is rated for. A simulated device rated 100 N
// palpating a knee whose contacts saturate at 12 N would otherwise show bars that never rise
// past an eighth (architecture.md#viewer).
#pragma once

#include "hapsim/core/device_profile.h"
#include "hapsim/world/world_description.h"

namespace hapsim {

/// The smallest of 1, 1.5, 2, 2.5, 3, 4, 5, 6, 8 × 10^k at or above `x_n` (> 0); 1 for x ≤ 0 or
/// non-finite x.
[[nodiscard]] double nice_force_ceiling_n(double x_n);

/// What a device's force display is rated for: a glove's finger actuator (or the tip, if
/// stronger), else the tip force.
[[nodiscard]] double device_rated_force_n(const DeviceProfile& profile);

/// nice_force_ceiling_n(min(rated_n, the scene's largest contact force)): a rig's gripper force
/// limit, else the largest max_force_n among the materials the bodies use. `rated_n` ≤ 0 or
/// non-finite counts as no rating.
[[nodiscard]] double force_display_scale_n(const WorldDescription& world, double rated_n);

}  // namespace hapsim
