#include "hapsim/render/force_scale.h"
#include "hapsim/rig/rig_controller.h"

#include <algorithm>
#include <array>
#include <cmath>

namespace hapsim {

double nice_force_ceiling_n(double x_n) {
  if (!(x_n > 0.0) || !std::isfinite(x_n)) {
    return 1.0;
  }
  constexpr std::array<double, 9> kSteps{1.0, 1.5, 2.0, 2.5, 3.0, 4.0, 5.0, 6.0, 8.0};
  double decade = std::pow(10.0, std::floor(std::log10(x_n)));
  for (int i = 0; i < 2; ++i, decade *= 10.0) {
    for (const double step : kSteps) {
      // A hair of tolerance: 4.0 must stay 4, not become 5 through rounding in log10/pow.
      if (step * decade >= x_n * (1.0 - 1e-12)) {
        return step * decade;
      }
    }
  }
  return 10.0 * decade;
}

double device_rated_force_n(const DeviceProfile& profile) {
  return profile.finger_count > 0 && profile.max_finger_force_n > 0.0
             ? std::max(profile.max_finger_force_n, profile.max_force_n)
             : profile.max_force_n;
}

double force_display_scale_n(const WorldDescription& world, double rated_n) {
  double ceiling_n = 0.0;
  if (const TeleopRigDescription* rig = rig_description(world)) {
    ceiling_n = rig->gripper.max_force_n;
  } else {
    for (const BodyDescription& body : world.bodies) {
      for (const SegmentDescription& seg : body.segments) {
        if (seg.material < world.materials.size()) {
          const double f = world.materials[seg.material].contact.max_force_n;
          if (std::isfinite(f)) {
            ceiling_n = std::max(ceiling_n, f);
          }
        }
      }
    }
  }
  const bool rated = rated_n > 0.0 && std::isfinite(rated_n);
  if (!(ceiling_n > 0.0)) {
    return nice_force_ceiling_n(rated ? rated_n : 10.0);
  }
  return nice_force_ceiling_n(rated ? std::min(rated_n, ceiling_n) : ceiling_n);
}

}  // namespace hapsim
