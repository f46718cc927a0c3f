// The seed's legacy force packet (knee paper 001 §3.1, SPEC §8): "The force data sent by the HP
// are encoded in four ints (4 bytes each), one per finger. The integer values are then scaled and
// type casted to floats in the range of 0 to 10" for the force host's D/A drivers. Here: 16
// bytes, four signed 32-bit integers in network byte order (big-endian), finger i's value
// round(1000 × f_i / f_max × 10), i.e. 0 to 10 000 for 0 to f_max (the glove's rated finger
// force): thousandths of the paper's 0–10 range.
//
// Pure bytes, no sockets: it lives beside the devices it drives (device/, layer 5), so the
// legacy glove (device/legacy_glove_device.h) decodes without the network layer; the UDP
// transport is net/legacy_force_udp.h. A packet that is short, long, or carries a value outside
// 0..10 000 (negative as int32 included) is refused as a whole and counted, never applied.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <span>

namespace hapsim {

inline constexpr int kLegacyForceFingers = 4;
inline constexpr std::size_t kLegacyForcePacketBytes = 16;
/// The value of a finger at its maximum force (10 on the paper's 0–10 range, in thousandths).
inline constexpr std::int32_t kLegacyForceFullScale = 10'000;

using LegacyForcePacket = std::array<std::byte, kLegacyForcePacketBytes>;
/// Newtons per finger, in the packet's order (finger 0 first).
using LegacyFingerForces = std::array<double, kLegacyForceFingers>;

enum class LegacyPacketVerdict : std::uint8_t {
  kAccepted,
  kShort,       ///< fewer than 16 bytes
  kLong,        ///< more than 16 bytes
  kOutOfRange,  ///< a value below 0 or above 10 000
  /// From a host other than the force host the source was told to take packets from (dropped by
  /// the source before it is read: anyone on the network can send a datagram).
  kOtherSender,
};
inline constexpr std::size_t kLegacyPacketVerdicts = 5;
using LegacyPacketCounts = std::array<std::uint64_t, kLegacyPacketVerdicts>;

[[nodiscard]] const char* legacy_verdict_name(LegacyPacketVerdict verdict) noexcept;

struct LegacyEncoded {
  LegacyForcePacket packet{};
  /// Fingers whose force was outside [0, f_max] (clamped) or not finite (sent as 0).
  int clamped_fingers = 0;
};

/// The packet for four finger forces, each clamped to [0, finger_max_n] (a NaN is 0). A finger
/// maximum that is not finite and > 0 encodes four zeros, all counted as clamped. haptic path
[[nodiscard]] LegacyEncoded encode_legacy_force(const LegacyFingerForces& finger_force_n,
                                                double finger_max_n) noexcept;

/// The verdict on one datagram; on kAccepted `out` holds the four forces, each in
/// [0, finger_max_n], otherwise `out` is untouched. A finger maximum that is not finite and > 0
/// refuses every packet (kOutOfRange). haptic path
[[nodiscard]] LegacyPacketVerdict decode_legacy_force(std::span<const std::byte> datagram,
                                                      double finger_max_n,
                                                      LegacyFingerForces& out) noexcept;

}  // namespace hapsim
