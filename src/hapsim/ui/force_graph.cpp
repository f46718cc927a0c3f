#include "hapsim/ui/force_graph.h"

#include "hapsim/render/force_scale.h"

#include <imgui.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>

namespace hapsim {

void ForceGraph::push(const std::vector<std::pair<std::string, double>>& bars) {
  if (series_.size() != bars.size()) {
    series_.assign(bars.size(), Series{});
    peaks_.assign(bars.size(), 0.0);
  }
  head_ = (head_ + 1) % kHistory;
  for (std::size_t i = 0; i < bars.size(); ++i) {
    Series& s = series_[i];
    s.label = bars[i].first;
    const double v = bars[i].second;
    if (!std::isfinite(v)) {
      saw_nonfinite_ = true;
    }
    s.latest = std::isfinite(v) ? v : 0.0;
    s.values[static_cast<std::size_t>(head_)] = static_cast<float>(s.latest);
    peaks_[i] = std::max(peaks_[i], s.latest);
  }
}

double ForceGraph::display_scale_n(double full_scale_n) const {
  const double scale = full_scale_n > 0.0 && std::isfinite(full_scale_n) ? full_scale_n : 1.0;
  double peak = 0.0;
  for (const double p : peaks_) {
    peak = std::max(peak, p);
  }
  return peak > scale ? nice_force_ceiling_n(peak) : scale;
}

std::string ForceGraph::fit_text(const std::vector<std::string>& candidates, float max_px,
                                 const std::function<float(const std::string&)>& width_px) {
  for (const std::string& c : candidates) {
    if (width_px(c) <= max_px) {
      return c;
    }
  }
  std::string cut = candidates.empty() ? std::string() : candidates.back();
  while (!cut.empty() && width_px(cut + ".") > max_px) {
    cut.pop_back();
  }
  return cut.empty() ? cut : cut + ".";
}

void ForceGraph::draw(double full_scale_n) const {
  const double scale = display_scale_n(full_scale_n);
  ImDrawList* draw = ImGui::GetWindowDrawList();
  const ImVec2 origin = ImGui::GetCursorScreenPos();
  const float width = ImGui::GetContentRegionAvail().x;
  const float height = 120.0f;
  const float line_h = ImGui::GetTextLineHeight();
  const std::size_t n = std::max<std::size_t>(series_.size(), 1);
  const float slot = width / static_cast<float>(n);
  const float bar_w = std::min(48.0f, 0.6f * slot);
  const float text_room = slot - 4.0f;  // a gap between neighbours' texts
  const ImU32 frame = IM_COL32(90, 90, 100, 255);
  const ImU32 bar = IM_COL32(kBarColour[0], kBarColour[1], kBarColour[2], kBarColour[3]);
  const ImU32 text = IM_COL32(230, 230, 230, 255);
  const auto measure = [](const std::string& t) { return ImGui::CalcTextSize(t.c_str()).x; };
  draw->AddRect(origin, ImVec2(origin.x + width, origin.y + height), frame);
  for (std::size_t i = 0; i < series_.size(); ++i) {
    const Series& s = series_[i];
    const float centre = origin.x + (static_cast<float>(i) + 0.5f) * slot;
    const float x0 = centre - 0.5f * bar_w;
    const auto fill = static_cast<float>(std::clamp(s.latest / scale, 0.0, 1.0));
    const float top = origin.y + height * (1.0f - fill);
    if (fill > 0.0f) {
      draw->AddRectFilled(ImVec2(x0, top), ImVec2(x0 + bar_w, origin.y + height), bar);
    }
    // The value over its bar, centred in its slot, as precise as the slot allows.
    char v2[32];
    char v1[32];
    char v0[32];
    std::snprintf(v2, sizeof v2, "%.2f N", s.latest);
    std::snprintf(v1, sizeof v1, "%.1f", s.latest);
    std::snprintf(v0, sizeof v0, "%.0f", s.latest);
    const std::string value = fit_text({v2, v1, v0}, text_room, measure);
    const float vx = centre - 0.5f * measure(value);
    draw->AddText(ImVec2(vx, std::clamp(top - line_h - 2.0f, origin.y + 1.0f,
                                        origin.y + height - line_h - 1.0f)),
                  text, value.c_str());
  }
  ImGui::Dummy(ImVec2(width, height));
  // The labels on a line of their own under the bars, each centred in and cut to its slot.
  const ImVec2 labels_at = ImGui::GetCursorScreenPos();
  for (std::size_t i = 0; i < series_.size(); ++i) {
    const std::string label = fit_text({series_[i].label}, text_room, measure);
    const float centre = labels_at.x + (static_cast<float>(i) + 0.5f) * slot;
    draw->AddText(ImVec2(centre - 0.5f * measure(label), labels_at.y), text, label.c_str());
  }
  ImGui::Dummy(ImVec2(width, line_h));
  // The caption on its own line: drawn over the first plot, a trace at full scale crossed it.
  char head[64];
  std::snprintf(head, sizeof head, "force history (N), full scale %.1f N, top to bottom:", scale);
  std::string caption = head;
  for (std::size_t i = 0; i < series_.size(); ++i) {
    caption += (i == 0 ? " " : ", ") + series_[i].label;
  }
  ImGui::TextWrapped("%s", caption.c_str());
  for (std::size_t i = 0; i < series_.size(); ++i) {
    const Series& s = series_[i];
    ImGui::PushID(static_cast<int>(i));
    // The oldest sample is the one after head_: the plot scrolls right to left.
    ImGui::PlotLines("##force", s.values.data(), kHistory, (head_ + 1) % kHistory, nullptr, 0.0f,
                     static_cast<float>(scale), ImVec2(width, 60.0f));
    ImGui::PopID();
  }
}

}  // namespace hapsim
