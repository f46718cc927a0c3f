#include "hapsim/device/resume_ceiling.h"

#include <algorithm>
#include <cmath>

namespace hapsim {
namespace {

// NaN and anything below 0 is 0, above 1 is 1: a broken ceiling fails safe.
double unit_gain(double gain) {
  return gain >= 0.0 ? std::min(gain, 1.0) : 0.0;
}

}  // namespace

ResumeCeiling::ResumeCeiling(double period_s, ForceRampParams ramp) noexcept
    : ramp_(ramp),
      step_(ramp.ramp_duration_s > 0.0 && period_s > 0.0 ? period_s / ramp.ramp_duration_s : 1.0) {}

double ResumeCeiling::update(double now_s, double external, bool soft_start) noexcept {
  if (soft_start) {
    ceiling_ = 0.0;
  }
  ceiling_ = std::min(1.0, ceiling_ + step_);
  ceiling_ = std::min(ceiling_, unit_gain(external));
  gap_cut_ = false;
  last_gap_s_ = 0.0;
  if (have_previous_) {
    last_gap_s_ = now_s - previous_s_;
    // A NaN time gives gain 0 (ramp_gain's "long ago"): the force restarts from zero.
    const double gap_gain = ramp_gain(last_gap_s_, true, ramp_);
    if (gap_gain < 1.0) {
      ceiling_ = std::min(ceiling_, gap_gain);
      gap_cut_ = true;
      ++gaps_;
    }
  }
  previous_s_ = now_s;
  have_previous_ = true;
  return ceiling_;
}

void ResumeCeiling::lower_to(double gain) noexcept {
  ceiling_ = std::min(ceiling_, unit_gain(gain));
}

}  // namespace hapsim
