// Device safety (architecture.md#force-and-safety): a command never exceeds the device's rated
// limits, never carries a NaN or inf, and ramps to zero within a bounded time when the simulation
// stalls or the device link drops. Pure functions of their arguments (testable without threads or
// clocks), plus a small per-cycle watchdog that strings them together for the haptic loop.
#pragma once

#include "hapsim/core/device_io.h"
#include "hapsim/core/device_profile.h"

#include <cstdint>

namespace hapsim {

/// What clamp_command() changed, so the loop can count and report it.
struct ClampReport {
  /// Non-finite values replaced by zero (a NaN component zeroes the whole tool force).
  int nonfinite_count = 0;
  /// The tool force was scaled down to max_force_n.
  bool force_clamped = false;
  /// Finger forces clamped to [0, max_finger_force_n] (or zeroed: beyond the device's fingers).
  int fingers_clamped = 0;
  /// Joint torques clamped to [-max, max] (or zeroed).
  int joints_clamped = 0;

  [[nodiscard]] bool changed() const {
    return nonfinite_count > 0 || force_clamped || fingers_clamped > 0 || joints_clamped > 0;
  }
};

/// |f| in newtons, scaled by the largest component first so a huge finite force cannot overflow:
/// the magnitude clamp_command() limits. A check against the device's rating must use this one
/// (the plain norm can read a few ulps above a force the clamp let through).
[[nodiscard]] double force_magnitude_n(const Vec3& f) noexcept;

/// haptic path: the command made safe for `profile`. A limit that is not finite and positive
/// allows nothing (a broken profile fails safe).
/// - a tool force with any non-finite component becomes zero (its direction is meaningless);
///   otherwise its magnitude is clamped to max_force_n (to within 1e-15 below), keeping the
///   direction;
/// - finger forces: non-finite -> 0, then clamped to [0, max_finger_force_n]; fingers the
///   device does not have (index >= profile.finger_count) are zeroed; finger_count is set to the
///   profile's;
/// - joint torques: non-finite -> 0, clamped to [-max_joint_torque_nm, max_joint_torque_nm];
///   slots past joint_count are zeroed.
[[nodiscard]] DeviceCommand clamp_command(const DeviceCommand& command,
                                          const DeviceProfile& profile,
                                          ClampReport* report = nullptr) noexcept;

struct ForceRampParams {
  /// How long a missing fresh cycle is tolerated before the ramp starts (a late cycle or two on
  /// a loaded machine should not make the force sag), seconds.
  double stale_timeout_s = 0.002;
  /// Ramp length from full to zero force, seconds.
  double ramp_duration_s = 0.008;

  /// Forces are zero at most this long after the last good cycle (default 10 ms).
  [[nodiscard]] double zero_by_s() const { return stale_timeout_s + ramp_duration_s; }
};

/// haptic path: the factor in [0, 1] applied to the last good command `since_good_s` seconds
/// after the last good cycle: 1 up to the grace time (stale_timeout_s while the device is
/// healthy, none once health is lost), then linear down to 0 over ramp_duration_s, and 0 after.
/// Monotone non-increasing in since_good_s. A non-finite or negative time counts as "long ago"
/// for NaN (gain 0) and as "just now" for negative values (gain 1).
[[nodiscard]] double ramp_gain(double since_good_s, bool healthy,
                               const ForceRampParams& params) noexcept;

/// haptic path: `last_good` scaled by ramp_gain() (all forces and torques). `last_good` must be
/// a clamp_command() result (finite, within limits); the ramp only ever shrinks it.
[[nodiscard]] DeviceCommand ramp_down(const DeviceCommand& last_good, double since_good_s,
                                      bool healthy, const ForceRampParams& params) noexcept;

/// Per-cycle safety for the haptic loop: clamps fresh commands and, when none arrives or the
/// device is unhealthy, ramps the last good one to zero. All state is fixed-size.
class ForceWatchdog {
 public:
  explicit ForceWatchdog(DeviceProfile profile, ForceRampParams params = {});

  /// haptic path. Call once per cycle at time `now_s` with the freshly computed command, or
  /// nullptr when the simulation produced none this cycle (stalled, input stale). Returns what to
  /// write to the device. A fresh command counts as good only while `device_healthy`.
  [[nodiscard]] DeviceCommand update(double now_s, const DeviceCommand* fresh_command,
                                     bool device_healthy) noexcept;

  /// True while the output is below the last good command because of a stall or health loss.
  [[nodiscard]] bool ramping() const noexcept { return ramping_; }
  /// The factor the last update() applied to the last good command (1 for a fresh one).
  [[nodiscard]] double output_gain() const noexcept { return gain_; }
  [[nodiscard]] std::uint64_t nonfinite_count() const noexcept { return nonfinite_count_; }
  [[nodiscard]] std::uint64_t clamped_cycles() const noexcept { return clamped_cycles_; }
  [[nodiscard]] std::uint64_t ramp_cycles() const noexcept { return ramp_cycles_; }

 private:
  DeviceProfile profile_;  // a copy: the watchdog must not outlive the limits it enforces
  ForceRampParams params_;
  DeviceCommand last_good_;
  double last_good_time_s_ = 0.0;
  bool have_good_ = false;
  bool ramping_ = false;
  double gain_ = 1.0;
  std::uint64_t nonfinite_count_ = 0;
  std::uint64_t clamped_cycles_ = 0;
  std::uint64_t ramp_cycles_ = 0;
};

}  // namespace hapsim
