#include "hapsim/ui/panel_refresh.h"

namespace hapsim {

PanelRefresh::PanelRefresh(double max_interval_s) : max_interval_s_(max_interval_s) {}

void PanelRefresh::pointer_event(bool over_panel) {
  if (over_panel || pointer_over_panel_) {
    pending_ = true;
  }
  pointer_over_panel_ = over_panel;
}

void PanelRefresh::other_event() {
  pending_ = true;
}

bool PanelRefresh::due(double now_s, bool imgui_captures) const {
  // `!(a < b)` rather than `a >= b`: a NaN interval or clock draws the panels every frame.
  return pending_ || imgui_captures || !(now_s - last_drawn_s_ < max_interval_s_);
}

void PanelRefresh::drawn(double now_s) {
  pending_ = false;
  last_drawn_s_ = now_s;
}

}  // namespace hapsim
