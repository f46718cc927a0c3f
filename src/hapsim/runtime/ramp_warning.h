// Saying, in words, that lateness held the force down for much of a run. A cycle more than the
// grace (2 ms) late cuts the force (to 0 N after 10 ms) and brings it back over 8 ms (HapticLoop's
// stall and gap handling): safe, but when a build or machine is too slow for the haptic rate that
// happens all the time, and a person feels little or nothing while the numbers show a counter.
#pragma once

#include <cstdint>
#include <string>

namespace hapsim {

/// Share of cycles (0..1) a ramp capped for lateness alone (HapticLoopStatus::late_ramp_cycles).
[[nodiscard]] double late_ramp_share(std::uint64_t cycles, std::uint64_t late_ramp_cycles);

/// One sentence when more than a fifth (21 % or more, as printed) of at least 1 000 cycles were
/// capped for lateness; "" otherwise.
[[nodiscard]] std::string late_ramp_warning(std::uint64_t cycles, std::uint64_t late_ramp_cycles);

}  // namespace hapsim
