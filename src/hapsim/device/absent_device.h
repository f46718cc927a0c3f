// A device that is not there: every read is unhealthy, every write goes nowhere. What a served
// world steps another user's tools with while that user's device host has not joined (or went
// silent): the world holds those tools with no force (World::set_device_input).
#pragma once

#include "hapsim/device/device.h"

namespace hapsim {

class AbsentDevice final : public Device {
 public:
  /// `profile` is reported as this device's (the rating a host that joins would bring).
  explicit AbsentDevice(const DeviceProfile& profile) : profile_(profile) {}

  /// haptic path: unhealthy, stamped `time_s`.
  [[nodiscard]] DeviceInput read(double time_s) noexcept override {
    DeviceInput input;
    input.time_s = time_s;
    input.healthy = false;
    return input;
  }
  /// haptic path: nothing to push.
  void write(const DeviceCommand& /*command*/) noexcept override {}
  [[nodiscard]] const DeviceProfile& profile() const noexcept override { return profile_; }
  [[nodiscard]] DeviceStatus status() const noexcept override {
    return {DeviceHealth::kFailed, "no device host has joined for these tools"};
  }

 private:
  DeviceProfile profile_;
};

}  // namespace hapsim
