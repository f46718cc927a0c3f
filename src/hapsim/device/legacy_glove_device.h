// The legacy force glove (knee paper 001 §3.1, SPEC §8): the seed's force host, a glove whose
// finger actuators are driven by legacy force packets (device/legacy_force_codec.h) from a
// simulation — `hapsim serve … --legacy-force-udp HOST:PORT` — rather than by hapsim's own
// local-model renderer. It is what `hapsim device --device legacy-glove` runs to put an old
// force host's protocol in the loop.
//
// Its input is a fixed glove pose (hand pose and four finger flexions: the packets carry no
// pose). What it renders is the newest valid packet's finger forces while packets keep coming:
// zero once the newest is older than `stale_after_s` (stale), failed after `failed_after_s`;
// write() is kept (last_command()) but does not drive the actuators: the packet is the force
// channel. Datagrams come from a LegacyPacketSource (a UDP socket, net/legacy_force_udp.h; a
// queue in tests), drained without waiting in read(): every pending one is judged and counted,
// the newest valid one kept. Clocks: only the host time passed to read() (no wall clock).
#pragma once

#include "hapsim/device/device.h"
#include "hapsim/device/legacy_force_codec.h"

#include <array>
#include <cstddef>
#include <cstdint>
#include <memory>
#include <optional>
#include <span>
#include <string>

namespace hapsim {

/// Where a legacy glove's datagrams come from.
class LegacyPacketSource {
 public:
  virtual ~LegacyPacketSource() = default;
  /// haptic path: the next pending datagram copied into `buffer`, without waiting. Returns its
  /// full length (larger than the buffer when it was longer: the rest is dropped), or nullopt
  /// when none is pending. Never throws.
  [[nodiscard]] virtual std::optional<std::size_t> receive(
      std::span<std::byte> buffer) noexcept = 0;
  /// Datagrams dropped so far for coming from a sender other than the force host (a source that
  /// cannot tell senders apart drops none). Never throws.
  [[nodiscard]] virtual std::uint64_t other_senders() const noexcept { return 0; }

 protected:
  LegacyPacketSource() = default;
  LegacyPacketSource(const LegacyPacketSource&) = default;
  LegacyPacketSource& operator=(const LegacyPacketSource&) = default;
  LegacyPacketSource(LegacyPacketSource&&) = default;
  LegacyPacketSource& operator=(LegacyPacketSource&&) = default;
};

struct LegacyGloveOptions {
  /// The glove's fixed pose (the packets carry none): hand position and orientation, device
  /// frame, and the four fingers' flexion (a relaxed, slightly curled hand).
  Vec3 p_world = Vec3::Zero();
  Quat q_world = Quat::Identity();
  std::array<double, kLegacyForceFingers> finger_rad{0.3, 0.3, 0.3, 0.3};
  /// Host time since the newest valid packet before the glove is stale (renders zero), then
  /// failed, seconds.
  double stale_after_s = 0.1;
  double failed_after_s = 1.0;
  /// At most this many datagrams judged per read(): a flood cannot hold the haptic thread (the
  /// rest wait for the next cycle).
  int max_datagrams_per_read = 256;
};

class LegacyGloveDevice final : public Device {
 public:
  /// `profile` must have at least 4 force fingers with a finite max_finger_force_n > 0 (the
  /// packet's full scale); `source` may be null (datagrams then come only through
  /// receive_datagram). Throws hapsim::Error otherwise.
  LegacyGloveDevice(DeviceProfile profile, std::unique_ptr<LegacyPacketSource> source,
                    LegacyGloveOptions options = {});

  /// haptic path: drains the source, then the fixed pose (healthy while packets are fresh).
  [[nodiscard]] DeviceInput read(double time_s) noexcept override;
  /// haptic path: kept as last_command(); the actuators follow the packets.
  void write(const DeviceCommand& command) noexcept override { last_command_ = command; }
  [[nodiscard]] const DeviceProfile& profile() const noexcept override { return profile_; }
  [[nodiscard]] DeviceStatus status() const noexcept override { return {health_, reason_}; }

  /// One datagram that arrived at host time `now_s`: judged, counted, and kept when valid and
  /// not older than the newest kept. read() calls it for each drained datagram. haptic path
  LegacyPacketVerdict receive_datagram(std::span<const std::byte> datagram, double now_s) noexcept;

  // For the device host (the thread that calls read()).
  /// The newest valid packet's finger forces, newtons, whatever its age (zero before any).
  [[nodiscard]] const LegacyFingerForces& newest_finger_force_n() const noexcept {
    return newest_n_;
  }
  /// Host time the newest valid packet arrived; nullopt before any.
  [[nodiscard]] std::optional<double> newest_received_s() const noexcept { return newest_s_; }
  /// What the glove renders as of the last read(): the newest finger forces while fresh, zero
  /// once stale or failed (4 finger channels, no tool force).
  [[nodiscard]] const DeviceCommand& rendered() const noexcept { return rendered_; }
  [[nodiscard]] const LegacyPacketCounts& counts() const noexcept { return counts_; }
  [[nodiscard]] std::uint64_t count(LegacyPacketVerdict verdict) const noexcept {
    return counts_[static_cast<std::size_t>(verdict)];
  }
  /// read() calls that stopped at max_datagrams_per_read with datagrams maybe still pending.
  [[nodiscard]] std::uint64_t drain_capped() const noexcept { return drain_capped_; }
  [[nodiscard]] const DeviceCommand& last_command() const noexcept { return last_command_; }

 private:
  DeviceProfile profile_;
  std::unique_ptr<LegacyPacketSource> source_;
  LegacyGloveOptions options_;
  std::string stale_reason_;  // built when constructed: the haptic path formats nothing
  std::string failed_reason_;
  std::string waiting_reason_;
  std::string never_reason_;

  std::array<std::byte, kLegacyForcePacketBytes + 1> buffer_{};  // +1: a long datagram shows
  LegacyFingerForces newest_n_{};
  std::optional<double> newest_s_;
  std::optional<double> first_read_s_;
  DeviceCommand rendered_;
  DeviceCommand last_command_;
  DeviceHealth health_ = DeviceHealth::kStale;
  std::string_view reason_;
  LegacyPacketCounts counts_{};
  std::uint64_t drain_capped_ = 0;
};

}  // namespace hapsim
