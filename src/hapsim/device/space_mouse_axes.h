// A 3D mouse's six axes as the viewer reads them (issue 13: the knee paper's 6D trackball drives
// the camera as well as the probe). SpacenavDevice implements SpaceMouseSource; the viewer's
// camera mapping (ui/space_mouse_camera.h) needs no libspnav, so it builds and is tested anywhere.
#pragma once

#include "hapsim/core/types.h"

#include <algorithm>
#include <cmath>

namespace hapsim {

/// One reading, each axis a fraction of full scale in [-1, 1], in spacenavd's frame: x right,
/// y up, z towards the user; `rotation` about those axes (right-handed: a twist of the cap
/// counter-clockwise seen from above is +y).
struct SpaceMouseAxes {
  Vec3 translation = Vec3::Zero();
  Vec3 rotation = Vec3::Zero();
};

/// `v` in [-1, 1] with readings inside ±`dead_zone` taken as zero (the puck never rests at 0),
/// rescaled past it so motion starts smoothly from zero and full deflection stays 1.
[[nodiscard]] inline double dead_zoned(double v, double dead_zone) {
  v = std::clamp(v, -1.0, 1.0);
  if (!(std::abs(v) > dead_zone) || !(dead_zone < 1.0)) {
    return 0.0;
  }
  return std::copysign((std::abs(v) - dead_zone) / (1.0 - dead_zone), v);
}

/// What the viewer asks of a 3D mouse besides the Device interface.
class SpaceMouseSource {
 public:
  virtual ~SpaceMouseSource() = default;
  /// The newest reading (normalised, no dead zone applied). Any thread.
  [[nodiscard]] virtual SpaceMouseAxes axes() const = 0;
  /// While true the puck drives the camera: the tool it would move holds still.
  virtual void set_drives_camera(bool drives_camera) = 0;

 protected:
  SpaceMouseSource() = default;
  SpaceMouseSource(const SpaceMouseSource&) = default;
  SpaceMouseSource& operator=(const SpaceMouseSource&) = default;
  SpaceMouseSource(SpaceMouseSource&&) = default;
  SpaceMouseSource& operator=(SpaceMouseSource&&) = default;
};

}  // namespace hapsim
