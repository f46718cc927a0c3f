// Where device input enters the world from outside (Python's World.step, a driver's sample), a
// non-finite number is refused before it is stepped or recorded: a NaN position would poison the
// world's state, and a recording holding one is refused whole by every reader.
#pragma once

#include "hapsim/core/device_io.h"

#include <cmath>
#include <cstddef>
#include <string>

namespace hapsim {

/// The first field of `in` that is not finite ("p_world[0] is nan"), or "" when all are (only
/// the first finger_count fingers and joint_count joints count). Not on the haptic path.
[[nodiscard]] inline std::string nonfinite_input_field(const DeviceInput& in) {
  const auto say = [](const std::string& name, double v) {
    return name + " is " + (std::isnan(v) ? "nan" : v > 0 ? "inf" : "-inf");
  };
  if (!std::isfinite(in.time_s)) {
    return say("time_s", in.time_s);
  }
  for (int k = 0; k < 3; ++k) {
    if (!std::isfinite(in.p_world[k])) {
      return say("p_world[" + std::to_string(k) + "]", in.p_world[k]);
    }
  }
  // Python's order, as q_world is given there: (w, x, y, z).
  const double q[4] = {in.q_world.w(), in.q_world.x(), in.q_world.y(), in.q_world.z()};
  for (int k = 0; k < 4; ++k) {
    if (!std::isfinite(q[k])) {
      return say("q_world[" + std::to_string(k) + "]", q[k]);
    }
  }
  for (int k = 0; k < in.finger_count && k < kMaxFingers; ++k) {
    const double v = in.finger_rad[static_cast<std::size_t>(k)];
    if (!std::isfinite(v)) {
      return say("finger_rad[" + std::to_string(k) + "]", v);
    }
  }
  for (int k = 0; k < in.joint_count && k < kMaxDeviceJoints; ++k) {
    const double v = in.joint_rad[static_cast<std::size_t>(k)];
    if (!std::isfinite(v)) {
      return say("joint_rad[" + std::to_string(k) + "]", v);
    }
  }
  return {};
}

}  // namespace hapsim
