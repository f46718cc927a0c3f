#include "hapsim/device/legacy_force_codec.h"

#include <algorithm>
#include <cmath>

namespace hapsim {
namespace {

bool usable_maximum(double finger_max_n) {
  return std::isfinite(finger_max_n) && finger_max_n > 0.0;
}

}  // namespace

const char* legacy_verdict_name(LegacyPacketVerdict verdict) noexcept {
  switch (verdict) {
    case LegacyPacketVerdict::kAccepted:
      return "accepted";
    case LegacyPacketVerdict::kShort:
      return "short";
    case LegacyPacketVerdict::kLong:
      return "long";
    case LegacyPacketVerdict::kOutOfRange:
      return "out of range";
    case LegacyPacketVerdict::kOtherSender:
      return "other sender";
  }
  return "unknown";
}

// haptic path
LegacyEncoded encode_legacy_force(const LegacyFingerForces& finger_force_n,
                                  double finger_max_n) noexcept {
  LegacyEncoded encoded;
  const bool usable = usable_maximum(finger_max_n);
  for (std::size_t i = 0; i < finger_force_n.size(); ++i) {
    const double f = finger_force_n[i];
    std::int32_t value = 0;
    if (!usable || !std::isfinite(f)) {
      ++encoded.clamped_fingers;
    } else {
      const double ratio = f / finger_max_n;
      if (ratio < 0.0 || ratio > 1.0) {
        ++encoded.clamped_fingers;
      }
      value = static_cast<std::int32_t>(
          std::lround(static_cast<double>(kLegacyForceFullScale) * std::clamp(ratio, 0.0, 1.0)));
    }
    // Network byte order: most significant byte first.
    const auto bits = static_cast<std::uint32_t>(value);
    for (std::size_t b = 0; b < 4; ++b) {
      encoded.packet[4 * i + b] = static_cast<std::byte>((bits >> (24 - 8 * b)) & 0xFFU);
    }
  }
  return encoded;
}

// haptic path
LegacyPacketVerdict decode_legacy_force(std::span<const std::byte> datagram, double finger_max_n,
                                        LegacyFingerForces& out) noexcept {
  if (datagram.size() < kLegacyForcePacketBytes) {
    return LegacyPacketVerdict::kShort;
  }
  if (datagram.size() > kLegacyForcePacketBytes) {
    return LegacyPacketVerdict::kLong;
  }
  if (!usable_maximum(finger_max_n)) {
    return LegacyPacketVerdict::kOutOfRange;
  }
  LegacyFingerForces forces{};
  for (std::size_t i = 0; i < forces.size(); ++i) {
    std::uint32_t bits = 0;
    for (std::size_t b = 0; b < 4; ++b) {
      bits = (bits << 8) | std::to_integer<std::uint32_t>(datagram[4 * i + b]);
    }
    const auto value = static_cast<std::int32_t>(bits);  // two's complement (C++20)
    if (value < 0 || value > kLegacyForceFullScale) {
      return LegacyPacketVerdict::kOutOfRange;
    }
    // The fraction first: it is at most exactly 1, so the force never exceeds f_max by a
    // rounding (f_max · 10 000 / 10 000 can).
    forces[i] = finger_max_n * (static_cast<double>(value) / kLegacyForceFullScale);
  }
  out = forces;
  return LegacyPacketVerdict::kAccepted;
}

}  // namespace hapsim
