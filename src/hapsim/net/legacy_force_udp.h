// The legacy force packet over UDP (device/legacy_force_codec.h, knee paper 001 §3.1: the force
// host was a second workstation on the Ethernet): `hapsim serve … --legacy-force-udp HOST:PORT`
// sends one packet per cycle with LegacyForceUdpSender; the `legacy-glove` device receives them
// with LegacyForceUdpReceiver (a LegacyPacketSource drained by LegacyGloveDevice::read()).
//
// Both sockets are non-blocking and set up entirely in their constructors (name resolution,
// bind), so send() and receive() are one system call each, allocate nothing and never wait.
// The receiver binds to loopback unless given an interface address (SPEC §8: services bind to
// loopback unless told otherwise), and takes datagrams only from its force host: anyone who can
// reach the port could otherwise push force into the glove. Datagrams from any other sender are
// dropped and counted (LegacyPacketVerdict::kOtherSender). A malformed HOST:PORT, an unknown host
// or a failed bind is one hapsim::Error line naming the option.
#pragma once

#include "hapsim/core/device_io.h"
#include "hapsim/core/device_profile.h"
#include "hapsim/device/legacy_force_codec.h"
#include "hapsim/device/legacy_glove_device.h"

#include <sys/socket.h>

#include <cstdint>
#include <memory>
#include <optional>
#include <span>
#include <string>
#include <string_view>

namespace hapsim::net {

struct UdpEndpoint {
  std::string host;  ///< a name or a numeric address (IPv6 without brackets)
  std::uint16_t port = 0;
};

/// "HOST:PORT", "[IPV6]:PORT" or "PORT" alone (then `default_host`). PORT is 1–65535, or 0
/// when `allow_port_zero` (an ephemeral port). Throws hapsim::Error(option, one line).
[[nodiscard]] UdpEndpoint parse_udp_endpoint(std::string_view text, std::string_view option,
                                             std::string_view default_host = "127.0.0.1",
                                             bool allow_port_zero = false);

struct LegacySenderCounts {
  std::uint64_t sent = 0;
  std::uint64_t send_failed = 0;      ///< the kernel did not take the datagram (buffer full, ...)
  std::uint64_t clamped_fingers = 0;  ///< finger forces outside [0, f_max] or NaN, clamped
};

class LegacyForceUdpSender {
 public:
  /// Resolves `host_port` ("HOST:PORT", or "PORT" for loopback) once and opens a non-blocking
  /// UDP socket. Throws hapsim::Error(option, one line).
  explicit LegacyForceUdpSender(std::string_view host_port,
                                std::string_view option = "--legacy-force-udp");
  ~LegacyForceUdpSender();
  LegacyForceUdpSender(const LegacyForceUdpSender&) = delete;
  LegacyForceUdpSender& operator=(const LegacyForceUdpSender&) = delete;
  LegacyForceUdpSender(LegacyForceUdpSender&&) = delete;
  LegacyForceUdpSender& operator=(LegacyForceUdpSender&&) = delete;

  /// haptic path: one datagram, never waits. False when the kernel did not take it (counted).
  bool send(const LegacyForcePacket& packet) noexcept;
  /// haptic path: four finger forces, newtons, as fractions of `finger_max_n`.
  bool send_fingers(const LegacyFingerForces& finger_force_n, double finger_max_n) noexcept;
  /// haptic path: the command's first four finger channels (missing ones are 0), e.g. the
  /// world's command clamped to the glove's profile, with its max_finger_force_n.
  bool send_command(const DeviceCommand& command, double finger_max_n) noexcept;

  [[nodiscard]] const UdpEndpoint& destination() const noexcept { return destination_; }
  [[nodiscard]] const LegacySenderCounts& counts() const noexcept { return counts_; }

 private:
  UdpEndpoint destination_;
  int fd_ = -1;
  sockaddr_storage address_{};
  socklen_t address_length_ = 0;
  LegacySenderCounts counts_;
};

class LegacyForceUdpReceiver final : public LegacyPacketSource {
 public:
  /// `bind_spec`: "PORT" binds 127.0.0.1:PORT; "ADDRESS:PORT" binds that interface's address
  /// ("0.0.0.0:PORT" every interface: only when told). PORT 0 takes an ephemeral port (see
  /// bound()). "…@HOST" or "…@HOST:PORT" names the force host, the only sender taken (any port
  /// of it unless one is given); without it a loopback bind takes its own address's datagrams
  /// only, and any other bind is refused (it would take force from anyone on the network).
  /// Throws hapsim::Error(option, one line).
  explicit LegacyForceUdpReceiver(std::string_view bind_spec,
                                  std::string_view option = "--legacy-force-bind");
  ~LegacyForceUdpReceiver() override;
  LegacyForceUdpReceiver(const LegacyForceUdpReceiver&) = delete;
  LegacyForceUdpReceiver& operator=(const LegacyForceUdpReceiver&) = delete;
  LegacyForceUdpReceiver(LegacyForceUdpReceiver&&) = delete;
  LegacyForceUdpReceiver& operator=(LegacyForceUdpReceiver&&) = delete;

  /// haptic path: the next pending datagram, never waits; its full length (MSG_TRUNC: a longer
  /// datagram than the buffer says so), or nullopt when none is pending.
  [[nodiscard]] std::optional<std::size_t> receive(std::span<std::byte> buffer) noexcept override;

  /// The numeric address and port actually bound.
  [[nodiscard]] const UdpEndpoint& bound() const noexcept { return bound_; }
  [[nodiscard]] std::uint64_t datagrams() const noexcept { return datagrams_; }
  /// recv() errors other than "nothing pending".
  [[nodiscard]] std::uint64_t errors() const noexcept { return errors_; }
  /// The force host datagrams are taken from (port 0: any port of it).
  [[nodiscard]] const UdpEndpoint& peer() const noexcept { return peer_; }
  [[nodiscard]] std::uint64_t other_senders() const noexcept override { return other_senders_; }

 private:
  [[nodiscard]] bool from_peer(const sockaddr_storage& source) const noexcept;

  UdpEndpoint bound_;
  UdpEndpoint peer_;
  sockaddr_storage peer_address_{};
  int fd_ = -1;
  std::uint64_t datagrams_ = 0;
  std::uint64_t errors_ = 0;
  std::uint64_t other_senders_ = 0;
};

/// The `legacy-glove` device (`hapsim device --device legacy-glove`): a LegacyGloveDevice fed by
/// a LegacyForceUdpReceiver bound per `bind_spec`. Throws hapsim::Error (one line).
[[nodiscard]] std::unique_ptr<LegacyGloveDevice> open_legacy_glove_udp(
    std::string_view bind_spec, DeviceProfile profile = device_profile("rutgers_master"),
    const LegacyGloveOptions& options = {}, std::string_view option = "--legacy-force-bind");

}  // namespace hapsim::net
