#include "hapsim/device/interactive_device.h"

#include <algorithm>
#include <cmath>

namespace hapsim {

InteractiveDevice::InteractiveDevice(DeviceProfile profile, const DeviceInput& initial,
                                     InteractiveDeviceOptions options)
    : profile_(std::move(profile)), options_(options), input_(initial), command_(DeviceCommand{}) {}

void InteractiveDevice::set_input(const DeviceInput& input) noexcept {
  input_.write_slot() = input;
  input_.publish();
}

const DeviceCommand& InteractiveDevice::last_command() noexcept {
  command_.update();
  return command_.read_slot();
}

void InteractiveDevice::set_connected(bool connected) noexcept {
  connected_.store(connected, std::memory_order_release);
}

DeviceInput InteractiveDevice::read(double time_s) noexcept {
  input_.update();
  DeviceInput in = input_.read_slot();
  const double tau = options_.position_smoothing_s;
  if (tau > 0.0 && in.p_world.allFinite()) {
    if (!have_smoothed_) {
      smoothed_p_world_ = in.p_world;
      have_smoothed_ = true;
    } else {
      const double dt = std::clamp(time_s - last_read_s_, 0.0, 1.0);
      smoothed_p_world_ += (1.0 - std::exp(-dt / tau)) * (in.p_world - smoothed_p_world_);
    }
    last_read_s_ = time_s;
    in.p_world = smoothed_p_world_;
  }
  in.time_s = time_s;
  in.healthy = in.healthy && connected_.load(std::memory_order_acquire);
  return in;
}

void InteractiveDevice::write(const DeviceCommand& command) noexcept {
  // Called by the haptic thread and, during a stall, the loop's supervisor — never both at once
  // (the loop serialises them), so this side of the buffer has one writer at a time.
  command_.write_slot() = command;
  command_.publish();
}

DeviceStatus InteractiveDevice::status() const noexcept {
  if (connected_.load(std::memory_order_acquire)) {
    return {};
  }
  return {DeviceHealth::kFailed, "the driving input went away"};
}

}  // namespace hapsim
