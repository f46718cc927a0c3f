// What a receiver decided about one sample from the network: applied, or dropped and why. Every
// gate counts its verdicts, so a broken or hostile peer shows up in a health report, never in
// the user's hand (SPEC §8).
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>

namespace hapsim::net {

enum class SampleVerdict : std::uint8_t {
  kAccepted,
  kMalformed,   ///< a non-finite number, or a key or count outside what the type allows
  kOutOfRange,  ///< finite but beyond the gate's limits of a believable sample
  kOtherScene,  ///< made for another scene than the one the receiver is in
  kOtherDevice,
  kOutOfOrder,  ///< not newer than the newest accepted for its key (late, duplicated, reordered)
  kStale,       ///< too old by the receiver's own count (never by another host's clock)
  /// From a host other than the one the receiver follows (a second `hapsim serve` on the
  /// session while the first still answers).
  kOtherHost,
};
inline constexpr std::size_t kSampleVerdicts = 8;

[[nodiscard]] const char* verdict_name(SampleVerdict verdict) noexcept;

/// Counts per verdict.
using VerdictCounts = std::array<std::uint64_t, kSampleVerdicts>;

}  // namespace hapsim::net
