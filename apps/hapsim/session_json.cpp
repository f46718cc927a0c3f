#include "session_json.h"

#include <vector>

namespace hapsim::app {

nlohmann::json realtime_json(const RealtimeSummary& rt) {
  return {{"rate_hz", rt.rate_hz},
          {"period_jitter_us",
           {{"p50", rt.period_jitter_us.p50},
            {"p99", rt.period_jitter_us.p99},
            {"max", rt.period_jitter_us.max}}},
          {"missed_deadlines", rt.missed_deadlines},
          {"scheduling", rt.realtime_priority ? "SCHED_FIFO" : "normal"},
          {"stall_events", rt.stall_events},
          {"ramp_cycles", rt.ramp_cycles},
          {"failed_steps", rt.failed_steps},
          {"resume_gaps", rt.resume_gaps},
          {"memory_locked", rt.memory_locked},
          {"haptic_page_faults", rt.haptic_page_faults},
          {"dropped_records", rt.dropped_records}};
}

nlohmann::json session_summary_json(const SceneDescription& scene, const World& world,
                                    const SessionSummary& s, const std::string& device_name) {
  nlohmann::json j;
  j["scene"] = scene.file.string();
  j["world"] = world.description().name;
  j["device"] = device_name;
  j["steps"] = s.steps;
  j["dt_s"] = s.steps > 0 ? s.simulated_s / static_cast<double>(s.steps) : 0.0;
  j["simulated_s"] = s.simulated_s;
  j["wall_s"] = s.wall_s;
  j["step_us"] = {{"p50", s.step_us.p50},
                  {"p99", s.step_us.p99},
                  {"max", s.step_us.max},
                  {"mean", s.step_us.mean}};
  j["pop_throughs"] = s.pop_throughs;
  j["max_proxy_penetration_m"] = s.max_proxy_penetration_m;
  j["max_force_limit_violations"] = s.max_force_limit_violations;
  j["clamped_cycles"] = s.clamped_cycles;
  j["nonfinite_commands"] = s.nonfinite_commands;
  j["peak_command_force_n"] = s.peak_command_force_n;
  j["dropped_contacts"] = s.dropped_contacts;
  j["missed_deadlines"] = s.missed_deadlines;
  j["recorded_frames"] = s.recorded_frames;
  if (s.realtime) {
    j["realtime"] = realtime_json(*s.realtime);
  }
  j["tools"] = nlohmann::json::array();
  for (const ToolSummary& t : s.tools) {
    j["tools"].push_back({{"name", t.name},
                          {"peak_force_n", t.peak_force_n},
                          {"mean_force_n", t.mean_force_n},
                          {"contact_steps", t.contact_steps}});
  }
  j["segments"] = nlohmann::json::array();
  for (const SegmentSummary& g : s.segments) {
    j["segments"].push_back({{"body", g.body},
                             {"name", g.name},
                             {"contacts", g.contacts},
                             {"peak_force_n", g.peak_force_n},
                             {"max_deflection_m", g.max_deflection_m}});
  }
  if (!s.bodies.empty()) {
    j["bodies"] = nlohmann::json::array();
    for (const BodySummary& b : s.bodies) {
      const auto xyz = [](const Vec3& v) { return std::vector<double>{v.x(), v.y(), v.z()}; };
      j["bodies"].push_back({{"name", b.name},
                             {"start_m", xyz(b.start_world)},
                             {"final_m", xyz(b.final_world)},
                             {"max_rise_m", b.max_rise_m},
                             {"final_speed_m_per_s", b.final_speed_m_per_s},
                             {"touching_at_end", b.touching_at_end},
                             {"nonfinite_steps", b.nonfinite_steps}});
    }
  }
  if (!s.sheets.empty()) {
    j["sheets"] = nlohmann::json::array();
    for (const SheetSummary& sh : s.sheets) {
      j["sheets"].push_back({{"name", sh.name},
                             {"max_depth_m", sh.max_depth_m},
                             {"final_depth_m", sh.final_depth_m}});
    }
  }
  std::vector<std::string> methods;
  for (const BodyDescription& b : world.description().bodies) {
    methods.emplace_back(to_string(b.method));
  }
  j["methods"] = methods;
  j["warnings"] = scene.warnings;
  j["stiffness_clamps"] = nlohmann::json::array();
  for (const StiffnessClamp& c : s.stiffness_clamps) {
    j["stiffness_clamps"].push_back({{"material", c.material},
                                     {"stiffness_n_per_m", c.stiffness_n_per_m},
                                     {"clamped_to_n_per_m", c.clamped_n_per_m}});
  }
  j["world_build_ms"] = world.build_ms();
  j["query_memory_bytes"] = world.query_memory_bytes();
  return j;
}

}  // namespace hapsim::app
