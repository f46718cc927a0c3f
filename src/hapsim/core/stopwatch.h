// Monotonic wall-clock timing for reports (build times, benchmark loops). Not for the haptic
// loop's deadline clock, which lives in runtime/.
#pragma once

#include <chrono>

namespace hapsim {

class Stopwatch {
 public:
  Stopwatch() : start_(Clock::now()) {}
  void restart() { start_ = Clock::now(); }
  [[nodiscard]] double elapsed_s() const {
    return std::chrono::duration<double>(Clock::now() - start_).count();
  }
  [[nodiscard]] double elapsed_ms() const { return elapsed_s() * 1e3; }

 private:
  using Clock = std::chrono::steady_clock;
  Clock::time_point start_;
};

}  // namespace hapsim
