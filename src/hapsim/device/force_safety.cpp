#include "hapsim/device/force_safety.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <utility>

namespace hapsim {
namespace {

// A limit that is NaN, infinite, negative or zero allows nothing: a broken profile fails safe.
double usable_limit(double limit) {
  return std::isfinite(limit) && limit > 0.0 ? limit : 0.0;
}

// Scaling to exactly max/norm can land a few ulps above max after rounding; this margin keeps
// the clamped magnitude at or below the limit ("never exceeds" is a hard guarantee).
constexpr double kClampMargin = 1.0 - 8.0 * std::numeric_limits<double>::epsilon();

// Clamps one scalar to [lo, hi] after replacing a non-finite value by zero.
double clamp_scalar(double value, double lo, double hi, ClampReport& report, int& clamped) {
  if (!std::isfinite(value)) {
    ++report.nonfinite_count;
    ++clamped;
    value = 0.0;
  }
  const double out = std::clamp(value, lo, hi);
  if (out != value) {
    ++clamped;
  }
  return out;
}

}  // namespace

double force_magnitude_n(const Vec3& f) noexcept {
  const double max_abs = f.cwiseAbs().maxCoeff();
  return max_abs > 0.0 ? max_abs * (f / max_abs).norm() : 0.0;
}

DeviceCommand clamp_command(const DeviceCommand& command, const DeviceProfile& profile,
                            ClampReport* report) noexcept {
  ClampReport local;
  ClampReport& r = report != nullptr ? *report : local;
  r = ClampReport{};
  DeviceCommand out;

  // Tool force: magnitude clamp keeps the direction the contact model chose.
  const double max_force_n = usable_limit(profile.max_force_n);
  const Vec3& f = command.force_world_n;
  const int nonfinite = static_cast<int>(!std::isfinite(f.x())) +
                        static_cast<int>(!std::isfinite(f.y())) +
                        static_cast<int>(!std::isfinite(f.z()));
  if (nonfinite > 0) {
    r.nonfinite_count += nonfinite;
    r.force_clamped = true;
    out.force_world_n = Vec3::Zero();
  } else {
    const double norm = force_magnitude_n(f);
    if (norm > max_force_n) {
      out.force_world_n = f * (max_force_n / norm * kClampMargin);
      r.force_clamped = true;
    } else {
      out.force_world_n = f;
    }
  }

  // Finger actuators push only: [0, max]. Fingers the device lacks get nothing.
  const int device_fingers = std::clamp(profile.finger_count, 0, kMaxFingers);
  const double max_finger_n = usable_limit(profile.max_finger_force_n);
  for (int i = 0; i < kMaxFingers; ++i) {
    const auto k = static_cast<std::size_t>(i);
    if (i < device_fingers) {
      out.finger_force_n[k] =
          clamp_scalar(command.finger_force_n[k], 0.0, max_finger_n, r, r.fingers_clamped);
    } else {
      const double v = command.finger_force_n[k];
      if (!std::isfinite(v)) {
        ++r.nonfinite_count;
      }
      if (v != 0.0) {
        ++r.fingers_clamped;
      }
      out.finger_force_n[k] = 0.0;
    }
  }
  out.finger_count = device_fingers;

  const int joints = std::clamp(command.joint_count, 0, kMaxDeviceJoints);
  const double max_torque_nm = usable_limit(profile.max_joint_torque_nm);
  for (int i = 0; i < kMaxDeviceJoints; ++i) {
    const auto k = static_cast<std::size_t>(i);
    if (i < joints) {
      out.joint_torque_nm[k] = clamp_scalar(command.joint_torque_nm[k], -max_torque_nm,
                                            max_torque_nm, r, r.joints_clamped);
    } else {
      if (!std::isfinite(command.joint_torque_nm[k])) {
        ++r.nonfinite_count;
      }
      if (command.joint_torque_nm[k] != 0.0) {
        ++r.joints_clamped;
      }
      out.joint_torque_nm[k] = 0.0;
    }
  }
  out.joint_count = joints;
  return out;
}

double ramp_gain(double since_good_s, bool healthy, const ForceRampParams& params) noexcept {
  if (std::isnan(since_good_s)) {
    return 0.0;
  }
  const double grace_s = healthy ? std::max(0.0, params.stale_timeout_s) : 0.0;
  if (since_good_s <= grace_s) {
    return 1.0;
  }
  const double ramp_s = params.ramp_duration_s;
  if (!(ramp_s > 0.0) || !std::isfinite(ramp_s)) {
    return 0.0;  // no usable ramp: cut at once rather than hold
  }
  const double gain = 1.0 - (since_good_s - grace_s) / ramp_s;
  // At the ramp's end rounding leaves ~1e-16 instead of 0; a device must see an exact zero.
  return gain < 1e-9 ? 0.0 : std::min(gain, 1.0);
}

DeviceCommand ramp_down(const DeviceCommand& last_good, double since_good_s, bool healthy,
                        const ForceRampParams& params) noexcept {
  const double gain = ramp_gain(since_good_s, healthy, params);
  DeviceCommand out = last_good;
  out.force_world_n = gain * last_good.force_world_n;
  for (double& f : out.finger_force_n) {
    f *= gain;
  }
  for (double& t : out.joint_torque_nm) {
    t *= gain;
  }
  return out;
}

ForceWatchdog::ForceWatchdog(DeviceProfile profile, ForceRampParams params)
    : profile_(std::move(profile)), params_(params) {
  last_good_.finger_count = std::clamp(profile_.finger_count, 0, kMaxFingers);
}

DeviceCommand ForceWatchdog::update(double now_s, const DeviceCommand* fresh_command,
                                    bool device_healthy) noexcept {
  if (fresh_command != nullptr && device_healthy) {
    ClampReport report;
    last_good_ = clamp_command(*fresh_command, profile_, &report);
    nonfinite_count_ += static_cast<std::uint64_t>(report.nonfinite_count);
    clamped_cycles_ += report.changed() ? 1 : 0;
    last_good_time_s_ = now_s;
    have_good_ = true;
    ramping_ = false;
    gain_ = 1.0;
    return last_good_;
  }
  if (!have_good_) {
    gain_ = 0.0;
    DeviceCommand zero;
    zero.finger_count = last_good_.finger_count;
    return zero;
  }
  const double since_good_s = now_s - last_good_time_s_;
  gain_ = ramp_gain(since_good_s, device_healthy, params_);
  ramping_ = gain_ < 1.0;
  ramp_cycles_ += ramping_ ? 1 : 0;
  return ramp_down(last_good_, since_good_s, device_healthy, params_);
}

}  // namespace hapsim
