// Rated limits of a haptic device: what the safety layer clamps to and what force algorithms
// must stay within (max stiffness keeps a penalty spring stable on that hardware).
#pragma once

#include "hapsim/core/types.h"

#include <optional>
#include <string>
#include <string_view>
#include <vector>

namespace hapsim {

struct DeviceProfile {
  /// Lookup key, lower case, e.g. "touch", "omega3", "rutgers_master", "simulated".
  std::string name;
  /// Human-readable model name.
  std::string display_name;
  /// Peak force on the tool / stylus tip, newtons. 0 for a device without a tip actuator (a glove).
  double max_force_n = 0.0;
  /// Force the device can hold indefinitely (thermal limit), newtons. Data only for now: the clamp
  /// uses the peak; a thermal (time-averaged) limiter needs a motor model.
  double max_continuous_force_n = 0.0;
  /// Highest rendering stiffness that stays stable on this device, N/m.
  double max_stiffness_n_per_m = 0.0;
  /// Highest rendering damping, N·s/m (CHAI3D publishes it beside stiffness).
  double max_damping_n_s_per_m = 0.0;
  /// Reachable positions in the device frame, metres (a box around the device origin).
  Box3 workspace_world{Vec3::Zero(), Vec3::Zero()};
  /// Force-actuated fingers (a force glove); 0 for a stylus.
  int finger_count = 0;
  /// Peak force per finger actuator, newtons (fingers push only: the range is [0, max]).
  double max_finger_force_n = 0.0;
  /// Peak torque per joint actuator, N·m; 0 when the device takes no joint torques (they are
  /// zeroed by the clamp, never passed through unchecked).
  double max_joint_torque_nm = 0.0;
  /// Slowest actuators (pneumatic) cannot follow a force step; empty when not rate-limited.
  std::optional<double> max_force_rate_n_per_s;
  /// Where the numbers come from and which of them are assumptions (shown by `hapsim info`).
  std::string source;
};

/// Every built-in profile, in a stable order.
[[nodiscard]] const std::vector<DeviceProfile>& builtin_device_profiles();

/// Names of the built-in profiles, in the same order.
[[nodiscard]] std::vector<std::string> device_profile_names();

/// The built-in profile called `name`. Throws hapsim::Error listing the known names otherwise.
[[nodiscard]] const DeviceProfile& device_profile(std::string_view name);

}  // namespace hapsim
