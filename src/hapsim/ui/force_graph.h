// The force column graph (one bar per finger, or the grasp force) and the scrolling force plot
// of the viewer's data area (papers 000 §4 and 001 §3.1): the bars change as the force changes,
// the plot keeps the last few seconds.
#pragma once

#include <array>
#include <string>
#include <utility>
#include <vector>

namespace hapsim {

class ForceGraph {
 public:
  /// Samples kept per series (at the frame rate: ~5 s at 60 fps).
  static constexpr int kHistory = 300;
  /// The bars' colour (RGBA): tests look for it in a screenshot.
  static constexpr std::array<unsigned char, 4> kBarColour = {255, 140, 20, 255};

  /// Adds this frame's values (label, newtons) to the history.
  void push(const std::vector<std::pair<std::string, double>>& bars);
  /// Draws the bars (0..full_scale_n) and the plot inside the current ImGui window.
  void draw(double full_scale_n) const;
  /// Largest value ever pushed, per series, and whether any was non-finite.
  [[nodiscard]] const std::vector<double>& peaks() const { return peaks_; }
  [[nodiscard]] bool saw_nonfinite() const { return saw_nonfinite_; }

 private:
  struct Series {
    std::string label;
    std::array<float, kHistory> values{};
    double latest = 0.0;
  };
  std::vector<Series> series_;
  std::vector<double> peaks_;
  int head_ = 0;
  bool saw_nonfinite_ = false;
};

}  // namespace hapsim
