// Where the snapshots of a scene look from (hapsim run --snapshot, hapsim watch --snapshot): a
// view named in the scene (--view) or given outright (--camera); else the knee from the front, a
// rig from the front-right, a table-top scene from well above, the final picture of a run
// framed on its last contact.
#pragma once

#include "commands.h"

#include "hapsim/core/error.h"
#include "hapsim/render/camera.h"
#include "hapsim/render/snapshot_writer.h"
#include "hapsim/rig/rig_controller.h"
#include "hapsim/scene/scene_description.h"
#include "hapsim/world/world.h"

#include <optional>
#include <span>
#include <string>

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
  if (rig_state(world) != nullptr) {
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
  return rig_state(world) != nullptr ? kTeleopYaw : kKneeYaw;
}
inline double snapshot_pitch_rad(const World& world) {
  return rig_state(world) != nullptr ? kTeleopPitch
                                     : (table_top(world) ? kTableTopPitch : kKneePitch);
}

/// The camera --view NAME or --camera SPEC chose (render/snapshot_writer.h chosen_camera), none
/// when neither was given; its error as a CommandError (exit 2, one line).
inline std::optional<OrbitCamera> chosen_snapshot_camera(const SceneDescription& scene,
                                                         const std::string& view,
                                                         const std::string& camera_spec) {
  try {
    return chosen_camera(scene, view, camera_spec);
  } catch (const Error& e) {
    throw CommandError(std::string(e.what()));
  }
}

/// The final picture's default: from the scene's usual direction, framing a box around
/// `contact_world` (a third of the scene's size each way) and the tools.
inline OrbitCamera framed_on_contact(const Box3& scene_bounds_world, const Vec3& contact_world,
                                     std::span<const Vec3> tools_world, double aspect,
                                     double yaw_rad, double pitch_rad) {
  const double half = std::max(0.05, 0.3 * scene_bounds_world.sizes().norm());
  Box3 box(contact_world - Vec3::Constant(half), contact_world + Vec3::Constant(half));
  for (const Vec3& t : tools_world) {
    box.extend(t);
  }
  return framed_camera(box, aspect, yaw_rad, pitch_rad);
}

}  // namespace hapsim::app
