// Does a scripted device ever bring a tool within reach of a body? A trajectory written for
// another scene, in other units or another frame plays without a single contact and the run
// reports zeros; run_setup.cpp samples it here before the run and warns (docs/scene-format.md,
// "Warnings").
#pragma once

#include "hapsim/device/device.h"
#include "hapsim/world/world.h"

#include <cstddef>
#include <string>

namespace hapsim {

/// Most device samples a check takes; longer trajectories are sampled more sparsely.
inline constexpr std::size_t kReachMaxSamples = 200'000;

struct TrajectoryReach {
  /// False when nothing was checked: no bodies, or a dynamic body (it may move into the path).
  bool checked = false;
  /// Over every sample and tool: the smallest gap between the tool's sphere and a segment's rest
  /// bounds (its axis-aligned box in the body frame), metres; 0 once a sphere touches a box. A
  /// lower bound on the distance to the surface itself (deflection only moves vertices inwards),
  /// so a gap > 0 means no contact is possible.
  double gap_m = 0.0;
  /// The body of that nearest box, the tool and the sample's time.
  std::string body;
  std::string tool;
  double time_s = 0.0;
};

/// Reads `device` at t = 0, dt, 2·dt … `duration_s` (at most kReachMaxSamples reads, evenly
/// spaced), stopping at the first sample within reach, and places the world's tools as step()
/// does: the device pose × each tool's offset, or a glove's fingertips from its joint angles.
/// Unusable inputs (unhealthy, non-finite) are skipped. The device's own state (a simulated
/// device's finished()) reflects the last read: read it again where the run starts.
[[nodiscard]] TrajectoryReach trajectory_reach(const World& world, Device& device,
                                               double duration_s, double dt_s);

}  // namespace hapsim
