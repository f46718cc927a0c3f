// The 3D mouse driving the viewer's orbit camera (the knee paper's 6D trackball turning the view),
// in "object" mode: the scene moves as the cap is pushed, as if held. Pure math on one reading
// and the frame's time, so the viewer and the tests share it.
//   twist (rotation y, counter-clockwise from above) turns the scene counter-clockwise: yaw −
//   tilt (rotation x, the cap's top towards the user) turns the scene's top towards the user:
//     more of its top shows, the eye goes up (pitch +)
//   push right / lift up (translation x / y) moves the scene right / up: the target the other way
//   pull towards the user (translation z) brings the scene nearer: distance shrinks
//   roll (rotation z) does nothing: the orbit camera keeps Z up.
// Each axis passes a dead zone and is scaled to a rate at full deflection.
#pragma once

#include "hapsim/device/space_mouse_axes.h"
#include "hapsim/render/camera.h"

namespace hapsim {

struct SpaceMouseCameraOptions {
  /// Readings inside ±dead_zone of full scale are zero.
  double dead_zone = 0.05;
  /// Orbit rate at full twist or tilt, rad/s.
  double full_turn_rad_per_s = 1.5;
  /// Pan rate at full push, in orbit distances per second (the same feel at any zoom).
  double full_pan_distances_per_s = 0.5;
  /// Zoom rate at full pull: the distance shrinks by e^(rate·t).
  double full_zoom_per_s = 1.0;
  /// A longer frame than this counts as this long (a stall must not fling the view).
  double max_dt_s = 0.1;
};

/// Moves `camera` by one reading held for `dt_s` seconds.
void drive_camera(OrbitCamera& camera, const SpaceMouseAxes& axes, double dt_s,
                  const SpaceMouseCameraOptions& options = {});

}  // namespace hapsim
