#include "hapsim/runtime/ramp_warning.h"

#include <algorithm>
#include <cmath>
#include <cstdio>

namespace hapsim {

namespace {
// A healthy run caps a few cycles after an occasional stall (8 ms of ramp back each); a fifth of
// all cycles is far beyond that, and fewer than 1 000 cycles say too little.
constexpr double kWarnPercent = 20.0;
constexpr std::uint64_t kMinCycles = 1000;
}  // namespace

double late_ramp_share(std::uint64_t cycles, std::uint64_t late_ramp_cycles) {
  if (cycles == 0) {
    return 0.0;
  }
  return std::min(1.0, static_cast<double>(late_ramp_cycles) / static_cast<double>(cycles));
}

std::string late_ramp_warning(std::uint64_t cycles, std::uint64_t late_ramp_cycles) {
  // Decided on the percentage as printed, so "20%" never appears under "more than a fifth".
  const double percent = std::round(100.0 * late_ramp_share(cycles, late_ramp_cycles));
  if (cycles < kMinCycles || !(percent > kWarnPercent)) {
    return {};
  }
  char text[256];
  std::snprintf(text, sizeof text,
                "%.0f%% of haptic cycles were capped because cycles came late (over 2 ms late cuts "
                "the force, to 0 N after 10 ms): contacts feel weaker and rougher than the model, "
                "or absent. This build or machine cannot keep the haptic rate.",
                percent);
  return text;
}

}  // namespace hapsim
