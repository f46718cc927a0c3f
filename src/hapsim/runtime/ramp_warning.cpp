#include "hapsim/runtime/ramp_warning.h"

#include <algorithm>
#include <cstdio>

namespace hapsim {

namespace {
// A healthy run ramps a few cycles after an occasional stall (8 a stall by default); a fifth of
// all cycles is far beyond that, and fewer than 1 000 cycles say too little.
constexpr double kWarnShare = 0.2;
constexpr std::uint64_t kMinCycles = 1000;
}  // namespace

double ramped_cycle_share(std::uint64_t cycles, std::uint64_t ramp_cycles) {
  if (cycles == 0) {
    return 0.0;
  }
  return std::min(1.0, static_cast<double>(ramp_cycles) / static_cast<double>(cycles));
}

std::string ramped_force_warning(std::uint64_t cycles, std::uint64_t ramp_cycles) {
  const double share = ramped_cycle_share(cycles, ramp_cycles);
  if (cycles < kMinCycles || !(share > kWarnShare)) {
    return {};
  }
  char text[256];
  std::snprintf(
      text, sizeof text,
      "%.0f%% of haptic cycles were held down by a safety ramp (a late cycle restarts the "
      "force from 0 N): contacts feel weaker and rougher than the model, or absent. This "
      "build or machine cannot keep the haptic rate.",
      100.0 * share);
  return text;
}

}  // namespace hapsim
