// The one interface every haptic device implements (simulated, replay, mouse, 3D mouse, network,
// real hardware): read an input sample, write a command, report rated limits and health.
#pragma once

#include "hapsim/core/device_profile.h"
#include "hapsim/core/device_io.h"

#include <string_view>

namespace hapsim {

enum class DeviceHealth {
  kConnected,  ///< Samples arrive and the device accepts commands.
  kStale,      ///< Connected, but no fresh sample arrived recently (a hiccup, may recover).
  kFailed,     ///< Link lost or the device reported an error; forces must ramp to zero.
};

/// Health and, unless connected, why. `reason` points into storage owned by the device and stays
/// valid until the next non-const call on it (no allocation on the haptic path).
struct DeviceStatus {
  DeviceHealth health = DeviceHealth::kConnected;
  std::string_view reason;
};

[[nodiscard]] constexpr std::string_view to_string(DeviceHealth health) {
  switch (health) {
    case DeviceHealth::kConnected:
      return "connected";
    case DeviceHealth::kStale:
      return "stale";
    case DeviceHealth::kFailed:
      return "failed";
  }
  return "unknown";
}

class Device {
 public:
  virtual ~Device() = default;

  /// haptic path: non-blocking, no allocation, no throw. The latest input for simulation time
  /// `time_s` (simulated/replay devices use it; hardware returns its newest sample, stamped).
  /// `healthy` in the result is false whenever status() is not kConnected.
  [[nodiscard]] virtual DeviceInput read(double time_s) noexcept = 0;

  /// haptic path: non-blocking, no allocation, no throw. The command must already be clamped
  /// to profile() (force_safety.h); a device may clamp again but never amplifies.
  /// Threads: the real-time loop calls write() from the haptic thread and, while a cycle is
  /// stalled, from its supervisor — possibly while the haptic thread is inside read(), never
  /// two write() calls at once.
  virtual void write(const DeviceCommand& command) noexcept = 0;

  /// Rated limits; constant for the device's lifetime.
  [[nodiscard]] virtual const DeviceProfile& profile() const noexcept = 0;

  [[nodiscard]] virtual DeviceStatus status() const noexcept = 0;

 protected:
  Device() = default;
  Device(const Device&) = default;
  Device& operator=(const Device&) = default;
  Device(Device&&) = default;
  Device& operator=(Device&&) = default;
};

}  // namespace hapsim
