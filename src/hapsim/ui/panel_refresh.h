// When the viewer's side panels are drawn again (ui/viewer.cpp, on a software rasteriser only).
//
// On Mesa's llvmpipe the panels' ~3 000 ImGui triangles and the copy of the whole window cost a
// quarter of a ~17 ms frame, yet the panels change only when the user points at them, types, or
// their figures move. So between panel frames the viewer draws and presents only the 3D view
// (ui/sub_buffer_present.h) and the panels' pixels stay as they were drawn. Their figures (time,
// forces, rates) are redrawn at least every `max_interval_s`: numbers are read slower than that,
// and the 3D view, force arrows included, still follows every frame.
#pragma once

#include <limits>

namespace hapsim {

class PanelRefresh {
 public:
  /// `max_interval_s`: the longest the panels go undrawn while nothing happens on them (> 0).
  explicit PanelRefresh(double max_interval_s);

  /// The pointer moved, a button was pressed or the wheel turned; `over_panel`: the pointer is
  /// over a panel now. Over a panel, or just off one (its hover highlight must go), the panels are
  /// due; over the 3D view (orbiting, probing) they are not.
  void pointer_event(bool over_panel);
  /// Anything else a panel may answer: a key, a character, a resize, the window exposed again.
  void other_event();
  /// Whether this frame draws the panels. `imgui_captures`: ImGui holds the pointer or the keyboard
  /// (the pointer is over a panel, a slider is dragged, a menu is open): every frame then.
  [[nodiscard]] bool due(double now_s, bool imgui_captures) const;
  /// The panels were drawn at `now_s`.
  void drawn(double now_s);

 private:
  double max_interval_s_;
  double last_drawn_s_ = -std::numeric_limits<double>::infinity();
  bool pending_ = true;
  bool pointer_over_panel_ = false;
};

}  // namespace hapsim
