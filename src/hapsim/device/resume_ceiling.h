// The haptic thread's own ceiling on the force it writes while the force comes back after being
// cut (architecture.md#real-time, issue 14): after the supervisor's stall ramp, the watchdog's
// ramp, a simulation's soft start, or a gap since the thread's own previous write that it measures
// itself. The gap is what makes a whole-process freeze safe (SIGSTOP/SIGCONT, a VM pause): both
// threads resume together, and without real-time priority the haptic thread often runs before the
// supervisor has noticed anything, so it must not rely on the supervisor's ceiling. A gap cuts the
// ceiling to the gain the supervisor's ramp would have reached by now (ramp_gain of the gap: full
// within the grace, zero beyond zero_by_s()), and the force then comes back over the ramp time, as
// after a stall the supervisor saw. A pure function of the times it is given (tests inject them).
#pragma once

#include "hapsim/device/force_safety.h"

#include <cstdint>

namespace hapsim {

class ResumeCeiling {
 public:
  /// `period_s`: the loop's period (> 0); the ceiling rises by period_s / ramp_duration_s a cycle.
  ResumeCeiling(double period_s, ForceRampParams ramp) noexcept;

  /// haptic path. Once per cycle, right before the device write at `now_s` (a steady clock, s):
  /// the ceiling in [0, 1] on this write's force. It rises one ramp step from the last one (from 0
  /// when `soft_start`), then is cut to `external` (another thread's ceiling, e.g. the supervisor's
  /// ramp gain: 1 for none; NaN counts as 0) and to the gain the gap since the previous call
  /// allows (none on the first call).
  [[nodiscard]] double update(double now_s, double external, bool soft_start) noexcept;
  /// haptic path: lowers the ceiling the next cycle rises from (the watchdog's own ramp).
  void lower_to(double gain) noexcept;

  [[nodiscard]] double ceiling() const noexcept { return ceiling_; }
  /// The time since the previous call, as the last update() measured it (0 on the first).
  [[nodiscard]] double last_gap_s() const noexcept { return last_gap_s_; }
  /// The last update() found a gap beyond the grace and cut the ceiling for it.
  [[nodiscard]] bool gap_cut() const noexcept { return gap_cut_; }
  /// Calls that found such a gap.
  [[nodiscard]] std::uint64_t gaps() const noexcept { return gaps_; }

 private:
  ForceRampParams ramp_;
  double step_ = 1.0;
  double ceiling_ = 1.0;
  double previous_s_ = 0.0;
  bool have_previous_ = false;
  double last_gap_s_ = 0.0;
  bool gap_cut_ = false;
  std::uint64_t gaps_ = 0;
};

}  // namespace hapsim
