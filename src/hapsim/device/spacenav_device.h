// A 3D mouse (3Dconnexion SpaceMouse and the like) through libspnav and the spacenavd daemon
// (architecture.md#devices): the puck's deflection is a velocity, integrated into the tool pose by
// a reader thread and handed to the haptic thread through InteractiveDevice's lock-free buffer. A
// 3D mouse renders no force; the viewer shows the force the tool would feel.
//
// Detected at run time: with no daemon answering (nothing plugged in, spacenavd not running)
// the constructor throws hapsim::Error with a message saying so. Built only where libspnav's
// headers exist (HAPSIM_WITH_SPNAV).
#pragma once

#include "hapsim/device/interactive_device.h"
#include "hapsim/device/space_mouse_axes.h"

#include <atomic>
#include <memory>
#include <mutex>
#include <string>
#include <thread>

namespace hapsim {

struct SpacenavOptions {
  /// Tool speed at full puck deflection, m/s, and turn rate, rad/s.
  double full_speed_m_per_s = 0.10;
  double full_turn_rad_per_s = 1.0;
  /// The puck's full-scale reading (spacenavd reports about ±350).
  double full_scale = 350.0;
  /// Readings below this fraction of full scale count as zero (the puck never rests at 0).
  double dead_zone = 0.05;
  /// Where the tool starts, world frame.
  Vec3 start_p_world = Vec3::Zero();
};

class SpacenavDevice final : public Device, public SpaceMouseSource {
 public:
  /// Connects to spacenavd. Throws hapsim::Error naming what is missing when it cannot.
  explicit SpacenavDevice(DeviceProfile profile, SpacenavOptions options = {});
  ~SpacenavDevice() override;
  SpacenavDevice(const SpacenavDevice&) = delete;
  SpacenavDevice& operator=(const SpacenavDevice&) = delete;
  SpacenavDevice(SpacenavDevice&&) = delete;
  SpacenavDevice& operator=(SpacenavDevice&&) = delete;

  [[nodiscard]] DeviceInput read(double time_s) noexcept override { return inner_.read(time_s); }
  void write(const DeviceCommand& command) noexcept override { inner_.write(command); }
  [[nodiscard]] const DeviceProfile& profile() const noexcept override { return inner_.profile(); }
  [[nodiscard]] DeviceStatus status() const noexcept override { return inner_.status(); }
  /// The newest command written (for the viewer's force display).
  [[nodiscard]] const DeviceCommand& last_command() noexcept { return inner_.last_command(); }

  [[nodiscard]] SpaceMouseAxes axes() const override;
  void set_drives_camera(bool drives_camera) override { drives_camera_.store(drives_camera); }

 private:
  void reader_main();

  SpacenavOptions options_;
  InteractiveDevice inner_;
  std::atomic<bool> stop_{false};
  std::atomic<bool> drives_camera_{false};
  // The newest reading for the viewer (its thread and the reader's; not the haptic path).
  mutable std::mutex axes_mutex_;
  SpaceMouseAxes axes_;
  std::thread reader_;
};

}  // namespace hapsim
