// A device with no hardware: plays a trajectory (loaded or built from waypoints) or a scripted
// function of time, and records what it was commanded. The embedded default device and the basis
// of reproducible tests and unattended scene runs.
#pragma once

#include "hapsim/device/device.h"
#include "hapsim/script/trajectory.h"

#include <functional>
#include <string>

namespace hapsim {

class SimulatedDevice final : public Device {
 public:
  /// Input as a function of simulation time (tests, scripted scenes). `duration_s`: after it the
  /// device reports finished() (the script is still called: it decides what "holding" means).
  using Script = std::function<DeviceInput(double time_s)>;

  /// Plays `trajectory` (precondition: not empty; make_trajectory / load_trajectory_csv ensure
  /// it). Before its start the first sample is held, after its end the last one.
  SimulatedDevice(DeviceProfile profile, Trajectory trajectory);
  SimulatedDevice(DeviceProfile profile, Script script, double duration_s = kInf);

  // Device
  [[nodiscard]] DeviceInput read(double time_s) noexcept override;
  void write(const DeviceCommand& command) noexcept override;
  [[nodiscard]] const DeviceProfile& profile() const noexcept override { return profile_; }
  [[nodiscard]] DeviceStatus status() const noexcept override;

  /// True once a read() was at or past the end of the trajectory / script duration.
  [[nodiscard]] bool finished() const noexcept { return finished_; }
  [[nodiscard]] double duration_end_s() const noexcept { return end_time_s_; }

  /// Test hook: simulate a link problem. read() then reports healthy = false unless kConnected.
  /// `reason` is copied here (not on the haptic path).
  void set_health(DeviceHealth health, std::string reason = {});

  // What the simulation sent.
  [[nodiscard]] const DeviceCommand& last_command() const noexcept { return last_command_; }
  [[nodiscard]] std::size_t command_count() const noexcept { return command_count_; }
  /// Largest |force_world_n| written so far, newtons.
  [[nodiscard]] double peak_force_n() const noexcept { return peak_force_n_; }
  /// Largest finger force written so far (any finger), newtons.
  [[nodiscard]] double peak_finger_force_n() const noexcept { return peak_finger_force_n_; }
  void reset_command_stats() noexcept;

 private:
  DeviceProfile profile_;
  Trajectory trajectory_;
  Script script_;
  double end_time_s_ = kInf;
  bool finished_ = false;
  DeviceHealth health_ = DeviceHealth::kConnected;
  std::string health_reason_;
  DeviceCommand last_command_;
  std::size_t command_count_ = 0;
  double peak_force_n_ = 0.0;
  double peak_finger_force_n_ = 0.0;
};

}  // namespace hapsim
