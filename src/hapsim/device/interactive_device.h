// A device driven by another thread of the same program (architecture.md#devices): the viewer's mouse and
// keyboard probe, a 3D mouse's reader thread, a script in a notebook. That thread sets the input
// whenever it likes; the haptic thread's read() takes the newest one, and the command the loop
// wrote is handed back so the viewer can show the force the device would render. Both hand-overs
// are lock-free triple buffers: the haptic path never waits for the UI.
#pragma once

#include "hapsim/core/triple_buffer.h"
#include "hapsim/device/device.h"

#include <atomic>
#include <string>

namespace hapsim {

struct InteractiveDeviceOptions {
  /// Time constant of a first-order filter on the position, seconds (0: none). A mouse moves
  /// the probe in 60 Hz steps; read at 1 kHz, each step would be a velocity spike (damping) and
  /// a force jump against a stiff surface. 10 ms smooths them and lags the hand by about as much.
  double position_smoothing_s = 0.0;
};

class InteractiveDevice final : public Device {
 public:
  explicit InteractiveDevice(DeviceProfile profile, const DeviceInput& initial = {},
                             InteractiveDeviceOptions options = {});

  // --- the driving thread (one) ---

  /// The input from now on (time_s is overwritten by read()).
  void set_input(const DeviceInput& input) noexcept;
  /// The newest command the loop wrote (after safety), as the user's hand would feel it.
  [[nodiscard]] const DeviceCommand& last_command() noexcept;
  /// Marks the link lost (the driver went away) or back; read() then reports it.
  void set_connected(bool connected) noexcept;

  // --- the haptic thread ---

  /// haptic path
  [[nodiscard]] DeviceInput read(double time_s) noexcept override;
  /// haptic path
  void write(const DeviceCommand& command) noexcept override;
  [[nodiscard]] const DeviceProfile& profile() const noexcept override { return profile_; }
  [[nodiscard]] DeviceStatus status() const noexcept override;

 private:
  DeviceProfile profile_;
  InteractiveDeviceOptions options_;
  TripleBuffer<DeviceInput> input_;
  // haptic thread only: the filtered position and when it was last read
  Vec3 smoothed_p_world_ = Vec3::Zero();
  double last_read_s_ = 0.0;
  bool have_smoothed_ = false;
  TripleBuffer<DeviceCommand> command_;
  std::atomic<bool> connected_{true};
};

}  // namespace hapsim
