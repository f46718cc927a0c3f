#include "hapsim/ui/force_graph.h"

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

void ForceGraph::draw(double full_scale_n) const {
  const double scale = full_scale_n > 0.0 ? full_scale_n : 1.0;
  ImDrawList* draw = ImGui::GetWindowDrawList();
  const ImVec2 origin = ImGui::GetCursorScreenPos();
  const float width = ImGui::GetContentRegionAvail().x;
  const float height = 120.0f;
  const std::size_t n = std::max<std::size_t>(series_.size(), 1);
  const float slot = width / static_cast<float>(n);
  const float bar_w = std::min(48.0f, 0.6f * slot);
  const ImU32 frame = IM_COL32(90, 90, 100, 255);
  const ImU32 bar = IM_COL32(kBarColour[0], kBarColour[1], kBarColour[2], kBarColour[3]);
  draw->AddRect(origin, ImVec2(origin.x + width, origin.y + height), frame);
  for (std::size_t i = 0; i < series_.size(); ++i) {
    const Series& s = series_[i];
    const float x0 = origin.x + (static_cast<float>(i) + 0.5f) * slot - 0.5f * bar_w;
    const auto fill = static_cast<float>(std::clamp(s.latest / scale, 0.0, 1.0));
    const float top = origin.y + height * (1.0f - fill);
    if (fill > 0.0f) {
      draw->AddRectFilled(ImVec2(x0, top), ImVec2(x0 + bar_w, origin.y + height), bar);
    }
    char value[32];
    std::snprintf(value, sizeof value, "%.2f N", s.latest);
    draw->AddText(ImVec2(x0, std::max(origin.y, top - 16.0f)), IM_COL32(230, 230, 230, 255), value);
  }
  ImGui::Dummy(ImVec2(width, height));
  // The labels on a line of their own under the bars (the first one must not join the graph's
  // line, where a full bar's value is written).
  for (std::size_t i = 0; i < series_.size(); ++i) {
    const float x = static_cast<float>(i) * slot + 0.5f * slot - 0.5f * bar_w + 8.0f;
    if (i == 0) {
      ImGui::SetCursorPosX(x);
    } else {
      ImGui::SameLine(x);
    }
    ImGui::TextUnformatted(series_[i].label.c_str());
  }
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
