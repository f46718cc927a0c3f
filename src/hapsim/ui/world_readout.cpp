#include "hapsim/ui/world_readout.h"

#include <imgui.h>

#include <algorithm>
#include <cstdio>

namespace hapsim {

std::string format_mm(const Vec3& p_m) {
  char text[96];
  std::snprintf(text, sizeof text, "%8.1f %8.1f %8.1f", p_m.x() * 1e3, p_m.y() * 1e3,
                p_m.z() * 1e3);
  return text;
}

void fill_world_readout(const World& world, const WorldScene& view, const WorldSnapshot& s,
                        SessionReadout& readout) {
  const WorldDescription& d = world.description();
  readout.time_s = s.time_s;
  readout.cycle = s.cycle;
  readout.tools.resize(s.tools.size());
  readout.bars.clear();
  readout.lines.clear();
  for (std::size_t t = 0; t < s.tools.size(); ++t) {
    ToolReadout& r = readout.tools[t];
    r.name = d.tools[t].name;
    r.p_world = s.tools[t].p_world;
    r.proxy_world = s.tools[t].proxy_world;
    r.force_n = s.tool_force_n[t];
    r.contacts = s.tools[t].contact_count;
    r.device = d.tools[t].device;
    r.user =
        d.device_hosts.empty() ? std::string() : d.device_hosts[static_cast<std::size_t>(r.device)];
    r.present = s.tools[t].present;
    readout.bars.emplace_back(r.name, r.force_n);
  }
  readout.contact_count = s.contact_count;
  readout.max_deflection_m = 0.0;
  for (const double x : s.deflection_m) {
    readout.max_deflection_m = std::max(readout.max_deflection_m, x);
  }
  // What is touched now.
  std::string touched;
  for (std::size_t i = 0; i < s.contact_count; ++i) {
    const WorldContact& c = s.contacts[i];
    const std::string& label = view.segment_label(world.flat_segment(c.body, c.segment).index());
    if (touched.find(label) == std::string::npos) {
      touched += (touched.empty() ? "" : ", ") + label;
    }
  }
  readout.lines.emplace_back("touching", touched.empty() ? "-" : touched);
  readout.lines.emplace_back("device pose (mm)", format_mm(s.input.p_world));
}

void draw_world_display_controls(WorldScene& view) {
  WorldSceneOptions o = view.options();
  bool changed = false;
  int colouring = static_cast<int>(o.colouring);
  ImGui::TextUnformatted("Colours");
  changed |= ImGui::RadioButton("tissue", &colouring, 0);
  ImGui::SameLine();
  changed |= ImGui::RadioButton("segments", &colouring, 1);
  ImGui::SameLine();
  changed |= ImGui::RadioButton("groups", &colouring, 2);
  ImGui::SameLine();
  changed |= ImGui::RadioButton("stress", &colouring, 3);
  if (colouring == 3) {
    // The legend: FEM bodies from their own colour (0) through yellow to red at this stress.
    ImGui::Text("FEM von Mises: red at %.2f kPa", view.fem_stress_full_scale_pa() * 1e-3);
  }
  o.colouring = static_cast<SegmentColouring>(colouring);
  changed |= ImGui::SliderInt("sphere-tree level", &o.sphere_tree_level, -1, 6,
                              o.sphere_tree_level < 0 ? "off" : "%d");
  changed |= ImGui::Checkbox("proxies", &o.show_proxies);
  ImGui::SameLine();
  changed |= ImGui::Checkbox("force arrows", &o.show_force_arrows);
  // The knee method's overlays (the knee paper's Fig. 3); drawn on segments that use it.
  changed |= ImGui::Checkbox("spheres of influence", &o.show_influence_spheres);
  if (ImGui::IsItemHovered()) {
    ImGui::SetTooltip("Each vertex group's sphere of influence (knee-method segments)");
  }
  changed |= ImGui::Checkbox("contact vertices", &o.show_contact_vertices);
  if (ImGui::IsItemHovered()) {
    ImGui::SetTooltip("The three vertices a touching tool's contact is tested against");
  }
  if (changed) {
    view.set_options(o);
  }
  if (ImGui::CollapsingHeader("Segments", ImGuiTreeNodeFlags_DefaultOpen)) {
    for (std::size_t i = 0; i < view.segment_count(); ++i) {
      bool visible = view.segment_visible(i);
      if (ImGui::Checkbox(view.segment_label(i).c_str(), &visible)) {
        view.set_segment_visible(i, visible);
      }
    }
  }
}

}  // namespace hapsim
