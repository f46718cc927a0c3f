#include "hapsim/runtime/session_json.h"

#include "hapsim/runtime/ramp_warning.h"

#include <string>
#include <vector>

namespace hapsim {

nlohmann::json realtime_json(const RealtimeSummary& rt) {
  nlohmann::json j = {{"rate_hz", rt.rate_hz},
                      {"cycles", rt.cycles},
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
                      {"dropped_records", rt.dropped_records},
                      {"late_ramp_cycles", rt.late_ramp_cycles},
                      {"late_ramp_share", late_ramp_share(rt.cycles, rt.late_ramp_cycles)}};
  if (const std::string warning = late_ramp_warning(rt.cycles, rt.late_ramp_cycles);
      !warning.empty()) {
    j["warning"] = warning;
  }
  return j;
}

nlohmann::json fem_summary_json(const FemSummary& f) {
  nlohmann::json bodies = nlohmann::json::array();
  for (const FemSummary::Body& b : f.bodies) {
    bodies.push_back({{"name", b.name},
                      {"tets", b.tets},
                      {"nodes", b.nodes},
                      {"elasticity", b.elasticity},
                      {"final_max_displacement_m", b.final_max_displacement_m}});
  }
  return {
      {"bodies", bodies},
      {"updates", f.updates},
      {"period_steps", f.period_steps},
      {"adopted", f.adopted},
      {"late_adopted", f.late_adopted},
      {"skipped_launches", f.skipped_launches},
      {"update_ms", {{"p50", f.update_ms_p50}, {"p99", f.update_ms_p99}, {"max", f.update_ms_max}}},
      {"failures", f.failures},
      {"error", f.error}};
}

namespace {

// A rig's figures (the session's TeleopSummary): its pick-and-place, the carried tool's force and
// the master's torque, the slave's tracking and collisions.
void add_rig_json(nlohmann::json& j, const TeleopSummary& t) {
  j["grasped"] = t.grasped;
  j["grasp_time_s"] = t.grasped ? nlohmann::json(t.grasp_time_s) : nlohmann::json(nullptr);
  j["release_time_s"] =
      t.release_time_s >= 0.0 ? nlohmann::json(t.release_time_s) : nlohmann::json(nullptr);
  j["ball_lift_m"] = t.ball_lift_m;
  j["ball_final_position_m"] = {t.ball_final_world.x(), t.ball_final_world.y(),
                                t.ball_final_world.z()};
  j["ball_target_error_m"] =
      t.target_error_m ? nlohmann::json(*t.target_error_m) : nlohmann::json(nullptr);
  j["peak_grasp_force_n"] = t.peak_grasp_force_n;
  j["max_sheet_deflection_m"] = t.max_sheet_deflection_m;
  j["max_slave_tracking_error_m"] = t.max_slave_tracking_error_m;
  j["slave_limited_steps"] = t.slave_limited_steps;
  j["peak_tool_force_n"] = t.peak_tool_force_n;
  j["peak_master_torque_nm"] = t.peak_master_torque_nm;
  j["mean_held_tool_force_n"] = t.mean_held_tool_force_n;
  j["held_steps"] = t.held_steps;
  j["slave_collisions"] = {
      {"steps", t.slave_collision_steps},
      {"pairs", t.slave_collisions},
      {"first_s", t.slave_collision_steps > 0 ? nlohmann::json(t.first_slave_collision_s)
                                              : nlohmann::json(nullptr)},
      {"bodies", t.slave_collision_bodies}};
}

}  // namespace

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
  j["started_inside"] = s.started_inside;
  j["max_proxy_penetration_m"] = s.max_proxy_penetration_m;
  j["max_force_limit_violations"] = s.max_force_limit_violations;
  j["clamped_cycles"] = s.clamped_cycles;
  j["nonfinite_commands"] = s.nonfinite_commands;
  j["peak_command_force_n"] = s.peak_command_force_n;
  j["dropped_contacts"] = s.dropped_contacts;
  j["missed_deadlines"] = s.missed_deadlines;
  j["recorded_frames"] = s.recorded_frames;
  if (!s.recording_error.empty()) {
    j["recording_error"] = s.recording_error;
  }
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
  if (s.fem) {
    j["fem"] = fem_summary_json(*s.fem);
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
  if (s.teleop) {
    add_rig_json(j, *s.teleop);
  }
  return j;
}

std::vector<std::string> run_failures(const RunSetup& setup, const SessionSummary& summary) {
  std::vector<std::string> failures;
  // A scripted pick-and-place must end with the ball within 5 mm of its target (a replay of one
  // is judged by its bit-for-bit comparison instead).
  if (summary.teleop && summary.teleop->target_error_m && !setup.replayed &&
      !summary.teleop->placed()) {
    failures.emplace_back("the pick-and-place did not end with the ball within 5 mm of the target");
  }
  if (summary.pop_throughs > 0) {
    failures.push_back(std::to_string(summary.pop_throughs) +
                       " pop-through(s): a tool went through a segment");
  }
  if (summary.max_force_limit_violations > 0) {
    failures.push_back(std::to_string(summary.max_force_limit_violations) +
                       " command(s) above the device's rated force");
  }
  if (!summary.recording_error.empty()) {
    failures.push_back("the recording stopped early: " + summary.recording_error);
  }
  return failures;
}

nlohmann::json run_summary_json(const RunSetup& setup, const SessionSummary& summary,
                                const RecordingDifference* replay) {
  nlohmann::json j = session_summary_json(setup.scene, *setup.world, summary, setup.device_name);
  // Stopped early (SIGINT in `hapsim run`): the figures are of the cycles run.
  j["interrupted"] = summary.interrupted;
  if (summary.teleop) {
    j["slave"] = setup.slave_name;
  }
  bool ok = run_failures(setup, summary).empty();
  if (replay != nullptr) {
    j["replay_identical"] = replay->identical;
    if (!replay->identical) {
      j["replay_difference"] = replay->message;
      ok = false;
    }
  }
  j["ok"] = ok;
  return j;
}

}  // namespace hapsim
