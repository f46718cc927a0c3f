// Where the snapshots of a scene look from (hapsim run --snapshot, hapsim watch --snapshot): the
// knee from the front, a rig from the front-right, a table-top scene from well above.
#pragma once

#include "hapsim/world/world.h"

namespace hapsim::app {

// The knee from the front (+Y) and a little medial (−X), slightly above: the patella faces the
// camera. The teleop scene from the front-right, above: robot, ball and sheet all in view.
constexpr double kKneeYaw = 1.95;
constexpr double kKneePitch = 0.3;
constexpr double kTeleopYaw = -0.9;
constexpr double kTeleopPitch = 0.45;
// A table-top scene (free bodies, a sheet, no rig) from the front, well above: at the knee's
// shallow angle a sheet 5 cm over a table reads as lying behind it.
constexpr double kTableTopPitch = 0.75;

// Whether the world has bodies that move or a sheet, and no rig: a table-top scene.
inline bool table_top(const World& world) {
  if (world.rig() != nullptr) {
    return false;
  }
  for (const BodyDescription& b : world.description().bodies) {
    if (b.kind == BodyKind::kDynamic || b.deformation == BodyDeformation::kGaussianSheet) {
      return true;
    }
  }
  return false;
}

/// The snapshot camera's azimuth and elevation for `world`.
inline double snapshot_yaw_rad(const World& world) {
  return world.rig() != nullptr ? kTeleopYaw : kKneeYaw;
}
inline double snapshot_pitch_rad(const World& world) {
  return world.rig() != nullptr ? kTeleopPitch : (table_top(world) ? kTableTopPitch : kKneePitch);
}

}  // namespace hapsim::app
