#include "hapsim/ui/space_mouse_camera.h"

#include <algorithm>
#include <cmath>

namespace hapsim {

void drive_camera(OrbitCamera& camera, const SpaceMouseAxes& axes, double dt_s,
                  const SpaceMouseCameraOptions& options) {
  if (!(dt_s > 0.0)) {
    return;
  }
  const double dt = std::min(dt_s, options.max_dt_s);
  const auto axis = [&options](double v) {
    return std::isfinite(v) ? dead_zoned(v, options.dead_zone) : 0.0;
  };
  const double twist = axis(axes.rotation.y());
  const double tilt = axis(axes.rotation.x());
  const double right = axis(axes.translation.x());
  const double up = axis(axes.translation.y());
  const double towards = axis(axes.translation.z());

  const double turn = options.full_turn_rad_per_s * dt;
  camera.yaw_rad -= turn * twist;
  camera.pitch_rad =
      std::clamp(camera.pitch_rad + turn * tilt, -OrbitCamera::kMaxPitch, OrbitCamera::kMaxPitch);
  const double pan_m = options.full_pan_distances_per_s * camera.distance_m * dt;
  camera.target_world -= pan_m * (right * camera.right_world() + up * camera.up_world());
  camera.distance_m =
      std::clamp(camera.distance_m * std::exp(-options.full_zoom_per_s * dt * towards),
                 OrbitCamera::kMinDistance, OrbitCamera::kMaxDistance);
}

}  // namespace hapsim
