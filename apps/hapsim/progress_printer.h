// Progress of a long command on stderr: one rewritten line on a terminal, one line per step
// otherwise (logs, CI). A step is a new label or another tenth of the way.
#pragma once

#include "hapsim/core/stopwatch.h"

#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <iostream>
#include <string>
#include <string_view>

namespace hapsim::app {

class ProgressPrinter {
 public:
  ProgressPrinter() : tty_(isatty(STDERR_FILENO) != 0) {}
  void operator()(std::string_view label, double fraction) {
    const int tenth = static_cast<int>(std::floor(std::clamp(fraction, 0.0, 1.0) * 10.0));
    if (label == last_label_ && tenth == last_tenth_) {
      return;
    }
    last_label_ = std::string(label);
    last_tenth_ = tenth;
    char prefix[64];
    std::snprintf(prefix, sizeof prefix, "[%3.0f%% %6.1fs] ", 100.0 * fraction, watch_.elapsed_s());
    if (tty_) {
      std::string line = prefix + last_label_;
      line.resize(std::max<std::size_t>(line.size(), width_), ' ');
      width_ = std::max(width_, line.size());
      std::cerr << '\r' << line << (fraction >= 1.0 ? "\n" : "") << std::flush;
    } else {
      std::cerr << prefix << last_label_ << '\n';
    }
  }

 private:
  bool tty_;
  std::string last_label_;
  int last_tenth_ = -1;
  std::size_t width_ = 0;
  Stopwatch watch_;
};

}  // namespace hapsim::app
