// Progress reporting for operations a user waits on (building trees for a big mesh, benchmarks).
// Libraries take a `ProgressFn` and call it; the app decides how (or whether) to show it.
#pragma once

#include <functional>
#include <string_view>

namespace hapsim {

/// Called with a short label and a fraction in [0, 1]. May be empty (no reporting).
using ProgressFn = std::function<void(std::string_view label, double fraction)>;

/// Calls `fn` if set. Cheap enough to call per item; callers throttle by passing fractions.
inline void report_progress(const ProgressFn& fn, std::string_view label, double fraction) {
  if (fn) {
    fn(label, fraction);
  }
}

}  // namespace hapsim
