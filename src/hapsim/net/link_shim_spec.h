// `--link-shim SPEC`: a LinkShim (net/link_shim.h) on the receive side of the real DDS path, so a
// delay, jitter, loss, bursts or an outage can be tried on the running system without root or
// netem. SPEC is comma-separated key=value pairs:
//   delay_ms, jitter_ms (extra U[0, jitter]), loss (0-1), burst_enter, burst_exit (0-1),
//   outage_at_s (from the start), outage_s, seed, ordered (0/1: keep the sending order).
#pragma once

#include "hapsim/net/link_shim.h"

#include <string_view>

namespace hapsim::net {

/// Throws hapsim::Error(option, one line) on an unknown key or a value out of range.
[[nodiscard]] LinkShimOptions parse_link_shim(std::string_view spec, std::string_view option);

}  // namespace hapsim::net
