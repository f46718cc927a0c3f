// A device driver loaded from a shared object through the public C ABI
// (include/hapsim/device_driver.h, docs/devices.md), wrapped as a hapsim::Device: how a vendor
// SDK (OpenHaptics, Force Dimension, libnifalcon) reaches hapsim without touching it.
//
// Loading checks everything before the device is used, and every failure is one hapsim::Error
// line naming the file and what is wrong: not a loadable shared object, the entry point
// hapsim_device_driver_v1 missing, another ABI version, a null function in the table, open()
// failing (with the driver's own message), rated limits that are not finite and >= 0.
//
// On the haptic path the wrapper trusts nothing the driver says: a state with a non-finite value
// (or a count out of range, or a zero quaternion) fails the device for good — the last good input
// is returned, unhealthy, and every later command sent to the driver is zero — and a command is
// clamped to the rated limits again before the driver sees it. A timestamp that stops changing
// makes the device stale, then failed (the driver's thread may have died while its health()
// still says OK).
#pragma once

#include "hapsim/device/device.h"
#include "hapsim/device_driver.h"

#include <array>
#include <atomic>
#include <cstdint>
#include <filesystem>
#include <memory>
#include <optional>
#include <string>
#include <string_view>

namespace hapsim {

struct PluginDeviceOptions {
  /// Host time without a new driver timestamp before the device is stale, then failed, seconds.
  double stale_after_s = 0.1;
  double failed_after_s = 1.0;
};

/// What the wrapper refused or could not do, counted since the device was opened.
struct PluginDeviceCounts {
  std::uint64_t reads = 0;
  std::uint64_t no_sample = 0;        ///< read_state() returned non-zero
  std::uint64_t bad_samples = 0;      ///< non-finite or out-of-range states (the first one fails)
  std::uint64_t commands_zeroed = 0;  ///< commands sent as zero: device failed, or a NaN in them
  std::uint64_t write_refused = 0;    ///< write_command() returned non-zero
};

class PluginDevice final : public Device {
 public:
  /// Loads `path`, checks its table, opens the device with `config` and reads its rated limits.
  /// Throws hapsim::Error (one line, where = "plugin PATH") on any failure.
  PluginDevice(const std::filesystem::path& path, const std::string& config,
               PluginDeviceOptions options = {});
  /// Writes a zero command, closes the device, unloads the shared object.
  ~PluginDevice() override;
  PluginDevice(const PluginDevice&) = delete;
  PluginDevice& operator=(const PluginDevice&) = delete;
  PluginDevice(PluginDevice&&) = delete;
  PluginDevice& operator=(PluginDevice&&) = delete;

  /// haptic path: the driver's newest sample, checked; see the file comment for the guards.
  [[nodiscard]] DeviceInput read(double time_s) noexcept override;
  /// haptic path: clamped to profile() again; all zero once the device failed.
  void write(const DeviceCommand& command) noexcept override;
  [[nodiscard]] const DeviceProfile& profile() const noexcept override { return profile_; }
  /// As of the last read() (or opening). The reason points into this device's storage.
  [[nodiscard]] DeviceStatus status() const noexcept override;

  /// The driver's name from its table (also profile().name).
  [[nodiscard]] const std::string& driver_name() const noexcept { return profile_.name; }
  [[nodiscard]] const std::filesystem::path& path() const noexcept { return path_; }
  /// Tool velocity of the newest good sample, device frame (DeviceInput has no velocity; a
  /// device host needs it for the local model and its DeviceState). Same thread as read().
  [[nodiscard]] const Vec3& velocity_world_m_per_s() const noexcept { return velocity_m_per_s_; }
  /// The driver's timestamp of the newest good sample, seconds on its own clock.
  [[nodiscard]] double driver_timestamp_s() const noexcept { return driver_timestamp_s_; }
  /// The command last handed to the driver (after the wrapper's clamp). Same thread as write().
  [[nodiscard]] const DeviceCommand& last_sent() const noexcept { return last_sent_; }
  /// Counts; reads are the read() thread's, writes the write() thread's.
  [[nodiscard]] PluginDeviceCounts counts() const noexcept;

 private:
  struct Library;  // the dlopen handle, closed last

  void fail_for_good(std::string_view what) noexcept;
  void set_status(DeviceHealth health, std::string_view reason) noexcept;

  std::filesystem::path path_;
  PluginDeviceOptions options_;
  std::unique_ptr<Library> library_;
  const hapsim_device_driver* table_ = nullptr;
  hapsim_driver_device* device_ = nullptr;
  DeviceProfile profile_;

  // read() thread
  DeviceInput last_good_;
  Vec3 velocity_m_per_s_ = Vec3::Zero();
  double driver_timestamp_s_ = 0.0;
  bool has_sample_ = false;
  std::optional<double> fresh_since_s_;  ///< host time the timestamp last changed (or first read)
  DeviceHealth health_ = DeviceHealth::kConnected;
  std::array<char, 192> reason_{};
  std::size_t reason_length_ = 0;
  std::string stale_reason_;  ///< built when opened: the haptic path formats nothing
  std::string failed_reason_;
  std::uint64_t reads_ = 0;
  std::uint64_t no_sample_ = 0;
  std::uint64_t bad_samples_ = 0;
  std::atomic<bool> failed_for_good_{false};

  // write() thread
  DeviceCommand last_sent_;
  std::atomic<std::uint64_t> commands_zeroed_{0};
  std::atomic<std::uint64_t> write_refused_{0};
};

/// The helper `hapsim device --device plugin:PATH.so` uses: a PluginDevice (throws
/// hapsim::Error, one line, on any failure).
[[nodiscard]] std::unique_ptr<PluginDevice> open_plugin_device(const std::filesystem::path& path,
                                                               const std::string& config,
                                                               PluginDeviceOptions options = {});

/// "plugin:PATH" → PATH; nullopt when `device_spec` does not start with "plugin:". Throws
/// hapsim::Error for "plugin:" with no path.
[[nodiscard]] std::optional<std::filesystem::path> plugin_path_from_device_spec(
    std::string_view device_spec);

}  // namespace hapsim
