// How a device host turns what the simulation sends into force: the raw force it computed, or the
// local contact model evaluated at the device's own fresh position (SPEC §8). One definition for
// the device host (net/device_host_client.h) and `hapsim bench network`'s link sweep
// (bench/link_sweep.h).
#pragma once

#include <cstdint>

namespace hapsim::net {

enum class ForceMode : std::uint8_t { kRaw, kLocalModel };

/// "raw" or "local-model", as the command line spells them.
[[nodiscard]] constexpr const char* to_string(ForceMode mode) noexcept {
  return mode == ForceMode::kRaw ? "raw" : "local-model";
}

}  // namespace hapsim::net
