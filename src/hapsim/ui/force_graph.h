// The force column graph (one bar per finger, or the grasp force) and the scrolling force plot
// of the viewer's data area (papers 000 §4 and 001 §3.1): the bars change as the force changes,
// the plot keeps the last few seconds.
#pragma once

#include <array>
#include <functional>
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
  /// Draws the bars and the plots inside the current ImGui window, full scale `full_scale_n`,
  /// or display_scale_n() once a force went past it. Each bar's value and label are fitted to
  /// its slot (fit_text), so neighbours never overlap.
  void draw(double full_scale_n) const;
  /// `full_scale_n`, or the next nice value (force_scale.h) above the largest force pushed when
  /// that went past it: a bar is never clipped unnoticed.
  [[nodiscard]] double display_scale_n(double full_scale_n) const;

  /// The first of `candidates` whose width (by `width_px`) fits `max_px`, else the last one cut
  /// short with a '.' until it fits (possibly empty).
  [[nodiscard]] static std::string fit_text(
      const std::vector<std::string>& candidates, float max_px,
      const std::function<float(const std::string&)>& width_px);
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
