#include "hapsim/device/simulated_device.h"

#include "hapsim/core/error.h"

#include <algorithm>
#include <cmath>
#include <utility>

namespace hapsim {

SimulatedDevice::SimulatedDevice(DeviceProfile profile, Trajectory trajectory)
    : profile_(std::move(profile)), trajectory_(std::move(trajectory)) {
  if (trajectory_.empty()) {
    throw Error("simulated device '" + profile_.name + "'", "trajectory has no samples");
  }
  end_time_s_ = trajectory_.end_time_s();
}

SimulatedDevice::SimulatedDevice(DeviceProfile profile, Script script, double duration_s)
    : profile_(std::move(profile)), script_(std::move(script)), end_time_s_(duration_s) {
  if (!script_) {
    throw Error("simulated device '" + profile_.name + "'", "empty script function");
  }
}

DeviceInput SimulatedDevice::read(double time_s) noexcept {
  DeviceInput in = script_ ? script_(time_s) : trajectory_.sample_at(time_s);
  in.time_s = time_s;
  in.healthy = in.healthy && health_ == DeviceHealth::kConnected;
  finished_ = time_s >= end_time_s_;
  return in;
}

void SimulatedDevice::write(const DeviceCommand& command) noexcept {
  last_command_ = command;
  ++command_count_;
  // A NaN must not hide in the peak (std::max(NaN, x) keeps x): report it as infinite.
  const double force = command.force_world_n.norm();
  peak_force_n_ = std::isnan(force) ? kInf : std::max(peak_force_n_, force);
  const int fingers = std::clamp(command.finger_count, 0, kMaxFingers);
  for (int i = 0; i < fingers; ++i) {
    const double f = command.finger_force_n[static_cast<std::size_t>(i)];
    peak_finger_force_n_ = std::isnan(f) ? kInf : std::max(peak_finger_force_n_, f);
  }
}

DeviceStatus SimulatedDevice::status() const noexcept {
  return {health_, health_reason_};
}

void SimulatedDevice::set_health(DeviceHealth health, std::string reason) {
  health_ = health;
  health_reason_ = std::move(reason);
}

void SimulatedDevice::reset_command_stats() noexcept {
  last_command_ = DeviceCommand{};
  command_count_ = 0;
  peak_force_n_ = 0.0;
  peak_finger_force_n_ = 0.0;
}

}  // namespace hapsim
