// Saying, in words, that the safety ramps held the force down for much of a run. A late haptic
// cycle restarts the force from 0 N and ramps it back (HapticLoop's stall and gap handling): safe,
// but when a build or machine is too slow for the haptic rate that happens after nearly every
// cycle, and a person feels almost nothing while the numbers only show a counter.
#pragma once

#include <cstdint>
#include <string>

namespace hapsim {

/// Share of cycles (0..1) whose output a ramp held below the simulation's command.
[[nodiscard]] double ramped_cycle_share(std::uint64_t cycles, std::uint64_t ramp_cycles);

/// One sentence when more than a fifth of at least 1 000 cycles were ramped; "" otherwise.
[[nodiscard]] std::string ramped_force_warning(std::uint64_t cycles, std::uint64_t ramp_cycles);

}  // namespace hapsim
