#include "hapsim/runtime/session.h"

#include "hapsim/collision/mesh_bvh.h"
#include "hapsim/core/error.h"
#include "hapsim/core/statistics.h"
#include "hapsim/deform/fem_body.h"
#include "hapsim/device/force_safety.h"
#include "hapsim/rig/rig_controller.h"
#include "hapsim/runtime/fem_thread.h"
#include "hapsim/runtime/ramp_warning.h"
#include "hapsim/runtime/record_drain.h"
#include "hapsim/runtime/tool_rendered_force.h"
#include "hapsim/runtime/world_haptic_client.h"
#include "hapsim/world/fem_coupling.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <ctime>
#include <limits>
#include <memory>
#include <optional>
#include <sstream>

namespace hapsim {
namespace {

// The independent pop-through check: an exact BVH over each closed proxy segment's rest surface
// (the surface the proxy is constrained against), built here, not taken from the world, so a
// fault in the world's chosen method cannot hide itself.
struct ProxyCheck {
  std::size_t body = 0;
  std::size_t segment = 0;
  Iso3 X_body_world = Iso3::Identity();
  Box3 bounds_body;
  std::unique_ptr<MeshBvh> bvh;
};

std::vector<ProxyCheck> make_proxy_checks(const World& world) {
  std::vector<ProxyCheck> checks;
  const WorldDescription& d = world.description();
  for (std::size_t b = 0; b < d.bodies.size(); ++b) {
    const BodyDescription& body = d.bodies[b];
    for (std::size_t s = 0; s < body.segments.size(); ++s) {
      const SegmentDescription& seg = body.segments[s];
      // Two-sided sheets have no inside to be caught in; the world tests cover crossing them.
      if (seg.two_sided || d.materials.at(seg.material).response != ContactResponse::kProxy) {
        continue;
      }
      ProxyCheck c;
      c.body = b;
      c.segment = s;
      c.X_body_world = body.X_world_body.inverse();
      c.bounds_body = seg.mesh.bounds();
      c.bvh = std::make_unique<MeshBvh>(seg.mesh);
      checks.push_back(std::move(c));
    }
  }
  return checks;
}

// Force a tool renders: its finger actuator's magnitude, or the tip force.
double command_peak_n(const DeviceCommand& command) {
  double peak = command.force_world_n.norm();
  for (int f = 0; f < command.finger_count; ++f) {
    peak = std::max(peak, command.finger_force_n[static_cast<std::size_t>(f)]);
  }
  return peak;
}

bool exceeds_limits(const DeviceCommand& command, const DeviceProfile& profile) {
  if (!std::isfinite(command.force_world_n.squaredNorm())) {
    return true;
  }
  // The clamp's own magnitude: the plain norm read 12.000000000000002 N for a force the clamp
  // let through on the 12 N omega.3, a violation that never was.
  if (force_magnitude_n(command.force_world_n) > profile.max_force_n) {
    return true;
  }
  for (int f = 0; f < command.finger_count; ++f) {
    const double v = command.finger_force_n[static_cast<std::size_t>(f)];
    if (!std::isfinite(v) || v < 0.0 || v > profile.max_finger_force_n) {
      return true;
    }
  }
  return false;
}

}  // namespace

namespace {

// The run's figures, from one cycle record at a time: the same code for an inline run and for
// the real-time loop's records (consumed off the haptic thread).
class SessionAccountant {
 public:
  SessionAccountant(const World& world, const DeviceProfile& profile, const SessionOptions& options,
                    std::size_t steps)
      : world_(world), profile_(profile), options_(options) {
    const WorldDescription& desc = world.description();
    summary_.tools.resize(desc.tools.size());
    force_sum_.assign(desc.tools.size(), 0.0);
    for (std::size_t t = 0; t < desc.tools.size(); ++t) {
      summary_.tools[t].name = desc.tools[t].name;
    }
    summary_.segments.resize(world.flat_segment_count());
    for (std::size_t b = 0; b < desc.bodies.size(); ++b) {
      for (std::size_t s = 0; s < desc.bodies[b].segments.size(); ++s) {
        SegmentSummary& seg =
            summary_.segments[world.flat_segment(BodyIndex{b}, LocalSegment{s}).index()];
        seg.body = desc.bodies[b].name;
        seg.name = desc.bodies[b].segments[s].name;
      }
    }
    if (options.check_pop_through) {
      checks_ = make_proxy_checks(world);
      proxy_inside_.assign(checks_.size() * desc.tools.size(), kOutside);
      last_proxy_world_.assign(desc.tools.size(), Vec3::Constant(kNever));
    }
    for (std::size_t b = 0; b < desc.bodies.size(); ++b) {
      if (desc.bodies[b].kind == BodyKind::kDynamic &&
          summary_.bodies.size() < static_cast<std::size_t>(kMaxCycleDynamicBodies)) {
        BodySummary body;
        body.name = desc.bodies[b].name;
        body.start_world = world.body_pose(b).translation();
        summary_.bodies.push_back(body);
        dynamic_bodies_.push_back(b);
      }
      if (world.sheet(b) != nullptr &&
          summary_.sheets.size() < static_cast<std::size_t>(kMaxCycleSheets)) {
        summary_.sheets.push_back(SheetSummary{desc.bodies[b].name, 0.0, 0.0});
      }
    }
    if (rig_state(world) != nullptr) {
      summary_.teleop.emplace();
      const TeleopRigDescription& rig = *rig_description(desc);
      summary_.teleop->has_ball = rig.ball_body != TeleopRigDescription::kNoBody;
      summary_.teleop->has_sheet = rig.sheet_body != TeleopRigDescription::kNoBody;
      carried_tool_ = rig.carried_tool;
      if (summary_.teleop->has_ball) {
        ball_start_z_ = world.body_pose(rig.ball_body).translation().z();
      }
    }
    // A served world runs until stopped: reserve a run of up to an hour, grow beyond.
    cost_us_.reserve(std::min<std::size_t>(steps, 3'600'000));
    touched_.assign(summary_.segments.size() * desc.tools.size(), 0);
  }

  void account(const CycleRecord& r) {
    const WorldDescription& desc = world_.description();
    cost_us_.push_back(r.cost_us);
    const DeviceCommand& out = r.output;
    if (exceeds_limits(out, profile_)) {
      ++summary_.max_force_limit_violations;
    }
    summary_.peak_command_force_n = std::max(summary_.peak_command_force_n, command_peak_n(out));
    summary_.dropped_contacts += static_cast<std::size_t>(std::max(0, r.dropped_contacts));
    summary_.pop_throughs += static_cast<std::size_t>(std::max(0, r.penalty_pop_throughs));
    std::fill(touched_.begin(), touched_.end(), std::uint8_t{0});
    for (std::int32_t i = 0; i < r.contact_count; ++i) {
      const WorldContact& c = r.contacts[static_cast<std::size_t>(i)];
      const std::size_t flat = world_.flat_segment(c.body, c.segment).index();
      SegmentSummary& seg = summary_.segments[flat];
      seg.peak_force_n = std::max(seg.peak_force_n, c.force_n);
      std::uint8_t& flag = touched_[flat * desc.tools.size() + c.tool.index()];
      if (flag == 0) {
        flag = 1;
        ++seg.contacts;
      }
    }
    // What the device renders of the tools' summed tip force (the safety layer may scale it).
    const double tip_n = r.world_command.force_world_n.norm();
    const double tip_scale = tip_n > 0.0 ? out.force_world_n.norm() / tip_n : 0.0;
    const std::size_t tools =
        std::min<std::size_t>(static_cast<std::size_t>(r.tool_count), summary_.tools.size());
    for (std::size_t t = 0; t < tools; ++t) {
      const ToolState& tool = r.tools[t];
      ToolSummary& ts = summary_.tools[t];
      const bool own = desc.tools[t].device == 0;
      const double f =
          tool_rendered_force_n(desc.tools[t], tool, out, tip_scale, t == carried_tool_);
      ts.peak_force_n = std::max(ts.peak_force_n, f);
      if (tool.contact_count > 0) {
        ++ts.contact_steps;
        force_sum_[t] += f;
      }
      // A proxy placed (the first step, or a jump: a reset, a device put down inside) inside a
      // body started there: one event, said once, not a pop-through per step until it leaves.
      const double radius = desc.tools[t].radius_m;
      if (!own && !world_.state().tools[t].input_usable) {
        // Not in the world (another user's device host has not joined, or left): nothing to
        // check, and it is placed afresh when it comes.
        if (!checks_.empty()) {
          last_proxy_world_[t] = Vec3::Constant(kNever);
          for (std::size_t k = 0; k < checks_.size(); ++k) {
            proxy_inside_[k * desc.tools.size() + t] = kOutside;
          }
        }
        continue;
      }
      const bool placed = !checks_.empty() && (last_proxy_world_[t].x() == kNever ||
                                               (tool.proxy_world - last_proxy_world_[t]).norm() >
                                                   std::max(radius, kPlacementJump_m));
      if (!checks_.empty()) {
        last_proxy_world_[t] = tool.proxy_world;
      }
      for (std::size_t k = 0; k < checks_.size(); ++k) {
        const ProxyCheck& c = checks_[k];
        std::uint8_t& was = proxy_inside_[k * desc.tools.size() + t];
        const Vec3 p_body = c.X_body_world * tool.proxy_world;
        if (c.bounds_body.exteriorDistance(p_body) > radius) {
          was = kOutside;
          continue;
        }
        const SurfacePoint sp = c.bvh->closest_point(p_body);
        const bool inside = sp.signed_distance < 0.0;
        if (inside && (was == kStartedInside || (was == kOutside && placed))) {
          if (was == kOutside) {
            ++summary_.started_inside;
            if (summary_.started_inside_first.empty()) {
              const BodyDescription& body = desc.bodies[c.body];
              char at[32];
              std::snprintf(at, sizeof at, " at %.3f s", r.time_s);
              summary_.started_inside_first = "tool '" + desc.tools[t].name + "' in " + body.name +
                                              "/" + body.segments[c.segment].name + at;
            }
          }
          was = kStartedInside;
          continue;
        }
        summary_.max_proxy_penetration_m =
            std::max(summary_.max_proxy_penetration_m, radius - sp.signed_distance);
        if (inside && was == kOutside) {
          ++summary_.pop_throughs;  // once per entry, however long it stays
        }
        was = inside ? kPoppedThrough : kOutside;
      }
    }
    if (r.has_teleop) {
      account_teleop(r.teleop);
    }
    for (std::size_t i = 0; i < std::min<std::size_t>(static_cast<std::size_t>(r.dynamic_count),
                                                      summary_.bodies.size());
         ++i) {
      BodySummary& body = summary_.bodies[i];
      const Vec3& p = r.dynamic_p_world[i];
      body.nonfinite_steps += p.allFinite() ? 0 : 1;
      body.max_rise_m = std::max(body.max_rise_m, p.z() - body.start_world.z());
      last_touching_[i] = r.dynamic_touching[i];
    }
    for (std::size_t i = 0;
         i < std::min<std::size_t>(static_cast<std::size_t>(r.sheet_count), summary_.sheets.size());
         ++i) {
      SheetSummary& sheet = summary_.sheets[i];
      sheet.max_depth_m = std::max(sheet.max_depth_m, r.sheet_depth_m[i]);
      sheet.final_depth_m = r.sheet_depth_m[i];
    }
    if (options_.recorder != nullptr && summary_.recording_error.empty()) {
      if (!options_.recorder->record(to_recorded_frame(r, profile_))) {
        ++summary_.recording_dropped_frames;
      } else {
        ++summary_.recorded_frames;
      }
      // The disk is touched here, between cycles (inline) or off the haptic thread (real time),
      // every 100 ms of the session at most: a killed run keeps all but its last 100 ms.
      if (options_.recorder->flush_due()) {
        flush_recording();
      }
    }
    ++summary_.steps;
  }

  void account_teleop(const TeleopStepResult& r) {
    TeleopSummary& t = *summary_.teleop;
    t.peak_tool_force_n = std::max(t.peak_tool_force_n, r.tool_force_world_n.norm());
    for (std::size_t j = 0; j < 3; ++j) {
      t.peak_master_torque_nm =
          std::max(t.peak_master_torque_nm, std::abs(r.command.joint_torque_nm[j]));
    }
    t.max_slave_tracking_error_m = std::max(t.max_slave_tracking_error_m, r.slave.position_error_m);
    t.slave_limited_steps += r.slave.acceleration_limited || r.slave.velocity_limited ? 1 : 0;
    if (r.slave_collisions > 0) {
      ++t.slave_collision_steps;
      t.slave_collisions += static_cast<std::size_t>(r.slave_collisions);
      if (t.first_slave_collision_s < 0.0) {
        t.first_slave_collision_s = r.time_s;
      }
      slave_collision_bodies_ |= r.slave_collision_bodies;
    }
    if (!t.has_ball) {
      return;  // a rig that palpates: no grasp, ball or sheet to follow
    }
    if (r.gripper.grasped_now && !t.grasped) {
      t.grasped = true;
      t.grasp_time_s = r.time_s;
    }
    if (r.gripper.released_now && t.grasped && t.release_time_s < 0.0) {
      t.release_time_s = r.gripper.released_at_s;  // when the pad left, not when that was sure
    }
    t.ball_lift_m = std::max(t.ball_lift_m, r.ball_p_world.z() - ball_start_z_);
    t.peak_grasp_force_n = std::max(t.peak_grasp_force_n, r.gripper.grasp_force_n());
    if (r.held) {
      ++t.held_steps;  // a running mean: no sum to lose digits in
      t.mean_held_tool_force_n += (r.tool_force_world_n.norm() - t.mean_held_tool_force_n) /
                                  static_cast<double>(t.held_steps);
    }
    t.max_sheet_deflection_m = std::max(t.max_sheet_deflection_m, r.sheet_depth_m);
    t.nonfinite_ball_steps += r.ball_p_world.allFinite() ? 0 : 1;
  }

  void note_deflection(std::size_t flat_segment, double deflection_m) {
    SegmentSummary& seg = summary_.segments[flat_segment];
    seg.max_deflection_m = std::max(seg.max_deflection_m, deflection_m);
  }

  // A failed write (a full disk) ends the recording, not the run: the recorder has cut the file
  // back to its last complete block, and the summary says why it stopped there.
  void flush_recording() {
    try {
      options_.recorder->flush();
    } catch (const Error& e) {
      summary_.recording_error = e.what();
    }
  }

  SessionSummary finish(double dt_s, double wall_s) {
    if (options_.recorder != nullptr && summary_.recording_error.empty()) {
      flush_recording();
    }
    summary_.wall_s = wall_s;
    summary_.simulated_s = static_cast<double>(summary_.steps) * dt_s;
    for (std::size_t t = 0; t < summary_.tools.size(); ++t) {
      ToolSummary& ts = summary_.tools[t];
      ts.mean_force_n =
          ts.contact_steps > 0 ? force_sum_[t] / static_cast<double>(ts.contact_steps) : 0.0;
    }
    summary_.step_us = summarize_samples(cost_us_);
    // The run has ended: the world is this thread's again.
    const WorldDescription& desc = world_.description();
    for (std::size_t i = 0; i < summary_.bodies.size(); ++i) {
      BodySummary& body = summary_.bodies[i];
      const std::size_t b = dynamic_bodies_[i];
      body.final_world = world_.body_pose(b).translation();
      body.final_speed_m_per_s = world_.state().bodies[b].v_world.norm();
      for (std::size_t other = 0; other < std::min<std::size_t>(desc.bodies.size(), 64); ++other) {
        if ((last_touching_[i] >> other) & 1U) {
          body.touching_at_end.push_back(desc.bodies[other].name);
        }
      }
    }
    if (summary_.teleop) {
      TeleopSummary& t = *summary_.teleop;
      if (t.has_ball) {
        t.ball_final_world = world_.body_pose(rig_description(desc)->ball_body).translation();
      }
      if (t.has_ball && options_.teleop_target_world) {
        t.target_error_m = (t.ball_final_world - *options_.teleop_target_world).norm();
      }
      for (std::size_t b = 0; b < std::min<std::size_t>(desc.bodies.size(), 64); ++b) {
        if ((slave_collision_bodies_ >> b) & 1U) {
          t.slave_collision_bodies.push_back(desc.bodies[b].name);
        }
      }
    }
    return std::move(summary_);
  }

 private:
  const World& world_;
  const DeviceProfile& profile_;
  const SessionOptions& options_;
  SessionSummary summary_;
  std::vector<double> force_sum_;
  std::vector<ProxyCheck> checks_;
  // Per check and tool: where the proxy was last step (a proxy inside after a placement is not a
  // pop-through, and one inside for many steps is one).
  static constexpr std::uint8_t kOutside = 0;
  static constexpr std::uint8_t kPoppedThrough = 1;
  static constexpr std::uint8_t kStartedInside = 2;
  // Further than this in one step (5 m/s at 1 kHz, beyond a hand) the proxy was put there.
  static constexpr double kPlacementJump_m = 0.005;
  static constexpr double kNever = std::numeric_limits<double>::infinity();
  std::vector<std::uint8_t> proxy_inside_;
  std::vector<Vec3> last_proxy_world_;
  std::vector<double> cost_us_;
  std::uint64_t slave_collision_bodies_ = 0;  // a bit per body index (TeleopStepResult)
  // Per-segment touch flags of one step, so a tool-step counts once per segment.
  std::vector<std::uint8_t> touched_;
  double ball_start_z_ = 0.0;
  std::size_t carried_tool_ = TeleopRigDescription::kNoTool;  // the tool a rig carries
  std::vector<std::size_t> dynamic_bodies_;                   // body index of each BodySummary
  std::array<std::uint64_t, kMaxCycleDynamicBodies> last_touching_{};
};

SessionSummary run_inline(World& world, Device& device, const SessionOptions& options,
                          std::size_t steps) {
  const WorldDescription& desc = world.description();
  SessionAccountant accountant(world, device.profile(), options, steps);
  ForceWatchdog watchdog(device.profile());
  CycleRecord record;
  const auto wall_start = std::chrono::steady_clock::now();
  const std::size_t progress_every = std::max<std::size_t>(1, steps / 100);
  // FEM updates run between cycles, outside the timed step (the same updates at the same steps
  // as when the step runs them itself: the same bits).
  struct FemBetweenCycles {
    explicit FemBetweenCycles(World& w) : world(w) { world.set_fem_deferred(true); }
    FemBetweenCycles(const FemBetweenCycles&) = delete;
    FemBetweenCycles& operator=(const FemBetweenCycles&) = delete;
    ~FemBetweenCycles() { world.set_fem_deferred(false); }
    World& world;
  } fem_between_cycles(world);
  for (std::size_t i = 0; i < steps; ++i) {
    if (options.stop != nullptr && options.stop->load(std::memory_order_relaxed)) {
      break;  // stopped from outside (a signal): the summary covers the cycles run
    }
    const double t_s = static_cast<double>(i) * options.dt_s;
    // The timed haptic cycle: read, step (collision, force, deformation), safety, write.
    const auto c0 = std::chrono::steady_clock::now();
    const DeviceInput input = device.read(t_s);
    const StepResult& result = world.step(input, options.dt_s);
    const bool healthy = input.healthy && device.status().health == DeviceHealth::kConnected;
    const DeviceCommand out = watchdog.update(t_s, &result.command, healthy);
    device.write(out);
    const auto c1 = std::chrono::steady_clock::now();
    world.advance_fem();
    // Bookkeeping (outside the timed cycle).
    fill_cycle_record(record, i, input, result, out,
                      std::chrono::duration<double, std::micro>(c1 - c0).count());
    accountant.account(record);
    if (options.on_record) {
      options.on_record(record);
    }
    for (std::size_t b = 0; b < desc.bodies.size(); ++b) {
      if (desc.bodies[b].kind != BodyKind::kDeformable) {
        continue;
      }
      for (std::size_t s = 0; s < desc.bodies[b].segments.size(); ++s) {
        accountant.note_deflection(world.flat_segment(BodyIndex{b}, LocalSegment{s}).index(),
                                   world.current_deflection_m(b, s));
      }
    }
    if (options.after_cycle) {
      options.after_cycle(i);
    }
    if ((i + 1) % progress_every == 0 || i + 1 == steps) {
      report_progress(options.progress, "run",
                      static_cast<double>(i + 1) / static_cast<double>(steps));
    }
  }
  SessionSummary summary = accountant.finish(
      options.dt_s,
      std::chrono::duration<double>(std::chrono::steady_clock::now() - wall_start).count());
  summary.clamped_cycles = watchdog.clamped_cycles();
  summary.nonfinite_commands = watchdog.nonfinite_count();
  return summary;
}

SessionSummary run_realtime(World& world, Device& device, const SessionOptions& options,
                            std::size_t steps) {
  SessionAccountant accountant(world, device.profile(), options, steps);
  WorldHapticClientOptions client_options;
  client_options.publish_snapshots = static_cast<bool>(options.on_snapshots);
  client_options.record_capacity = 4096;  // 4 s of slack for the bookkeeping below
  client_options.observer = options.observer;
  WorldHapticClient client(world, client_options);
  if (options.on_snapshots) {
    options.on_snapshots(client.snapshots());
  }
  if (options.on_client) {
    options.on_client(&client);
  }
  // Whoever holds the client or its snapshots lets go before they go, however this returns.
  struct HandBack {
    explicit HandBack(const SessionOptions& o) : options(o) {}
    HandBack(const HandBack&) = delete;
    HandBack& operator=(const HandBack&) = delete;
    HandBack(HandBack&&) = delete;
    HandBack& operator=(HandBack&&) = delete;
    const SessionOptions& options;
    ~HandBack() {
      if (options.on_client) {
        options.on_client(nullptr);
      }
      if (options.on_snapshots) {
        options.on_snapshots(nullptr);  // the buffer goes with the client
      }
    }
  };
  std::optional<HandBack> hand_back;
  hand_back.emplace(options);
  HapticLoopOptions loop_options = options.loop;
  loop_options.period_s = options.dt_s;
  loop_options.max_cycles = steps;
  loop_options.missed_period_s = 2.0 * options.dt_s;
  HapticLoop loop(device, client, loop_options);
  const FemThread fem_thread(world);  // FEM bodies step on their own thread meanwhile
  SpscRing<CycleRecord>& records = *client.records();
  const std::size_t progress_every = std::max<std::size_t>(1, steps / 100);
  std::size_t accounted = 0;
  const auto wall_start = std::chrono::steady_clock::now();
  loop.start();
  drain_until_stopped(
      loop, records,
      [&](const CycleRecord& r) {
        accountant.account(r);
        if (options.on_record) {
          options.on_record(r);
        }
        if (++accounted % progress_every == 0) {
          report_progress(options.progress, "run (real time)",
                          static_cast<double>(accounted) / static_cast<double>(steps));
        }
      },
      options.stop);
  loop.wait();
  hand_back.reset();
  const double wall_s =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - wall_start).count();
  for (std::size_t flat = 0; flat < world.flat_segment_count(); ++flat) {
    accountant.note_deflection(flat, client.max_deflection_m()[flat]);
  }
  SessionSummary summary = accountant.finish(options.dt_s, wall_s);
  const HapticLoopStatus st = loop.status();
  summary.clamped_cycles = st.clamped_cycles;
  summary.nonfinite_commands = st.nonfinite_commands;
  summary.missed_deadlines = st.missed_deadlines;
  const RealtimeSummary rt = realtime_summary(st, client.dropped_records());
  summary.realtime = rt;
  summary.fem = fem_summary(world);
  if (summary.fem && fem_thread.failures() > 0) {
    // The FEM thread stopped at its first failed update; the haptic path kept its last models.
    summary.fem->failures += fem_thread.failures();
    summary.fem->error = fem_thread.error();
  }
  return summary;
}

}  // namespace

RealtimeSummary realtime_summary(const HapticLoopStatus& status, std::size_t dropped_records) {
  RealtimeSummary rt;
  rt.rate_hz = status.rate_hz;
  rt.period_jitter_us = status.period_jitter_us;
  rt.missed_deadlines = status.missed_deadlines;
  rt.realtime_priority = status.realtime_priority;
  rt.stall_events = status.stall_events;
  rt.ramp_cycles = status.ramp_cycles;
  rt.cycles = status.cycles;
  rt.late_ramp_cycles = status.late_ramp_cycles;
  rt.failed_steps = status.failed_steps;
  rt.resume_gaps = status.resume_gaps;
  rt.memory_locked = status.memory_locked;
  rt.haptic_page_faults = status.haptic_page_faults;
  rt.dropped_records = dropped_records;
  return rt;
}

std::string format_realtime_summary(const RealtimeSummary& rt) {
  char line[320];
  std::snprintf(line, sizeof line,
                "real time: %.2f Hz (%s), period jitter p50 %.1f us, p99 %.1f us, max %.1f us; "
                "missed deadlines (period > 2x): %zu; stalls ramped: %zu; gaps ramped: %zu\n",
                rt.rate_hz, rt.realtime_priority ? "SCHED_FIFO" : "normal scheduling",
                rt.period_jitter_us.p50, rt.period_jitter_us.p99, rt.period_jitter_us.max,
                rt.missed_deadlines, rt.stall_events, rt.resume_gaps);
  std::string text = line;
  if (rt.dropped_records > 0 || rt.failed_steps > 0) {
    text += "real time: " + std::to_string(rt.dropped_records) +
            " cycle record(s) not accounted (bookkeeping fell behind), " +
            std::to_string(rt.failed_steps) + " failed step(s)\n";
  }
  if (const std::string warning = late_ramp_warning(rt.cycles, rt.late_ramp_cycles);
      !warning.empty()) {
    text += "real time: " + warning + "\n";
  }
  return text;
}

SessionSummary run_session(World& world, Device& device, const SessionOptions& options) {
  if (!(options.duration_s > 0.0) || !std::isfinite(options.duration_s)) {
    throw Error("session", "duration must be a finite number of seconds > 0, got " +
                               std::to_string(options.duration_s));
  }
  if (!(options.dt_s > 0.0) || !(options.dt_s <= 0.1)) {
    throw Error("session", "dt must be in (0, 0.1] s, got " + std::to_string(options.dt_s));
  }
  const double wanted_steps = options.duration_s / options.dt_s;
  if (!(wanted_steps <= max_session_steps(options.realtime))) {
    char text[160];
    std::snprintf(text, sizeof text, "%g s at dt %g s is %.3g steps; at most %.0e %s",
                  options.duration_s, options.dt_s, wanted_steps,
                  max_session_steps(options.realtime),
                  options.realtime ? "in real time" : "as fast as possible");
    throw Error("session", text);
  }
  const auto steps = static_cast<std::size_t>(std::llround(wanted_steps));
  if (steps == 0) {
    throw Error("session", "duration " + std::to_string(options.duration_s) +
                               " s is shorter than one step of " + std::to_string(options.dt_s) +
                               " s");
  }
  SessionSummary summary = options.realtime ? run_realtime(world, device, options, steps)
                                            : run_inline(world, device, options, steps);
  summary.interrupted = options.stop != nullptr && options.stop->load(std::memory_order_relaxed) &&
                        summary.steps < steps;
  summary.stiffness_clamps = stiffness_clamps(world);
  if (!summary.fem) {
    summary.fem = fem_summary(world);
  }
  return summary;
}

std::unique_ptr<SessionRecorder> make_session_recorder(const std::filesystem::path& path,
                                                       const World& world,
                                                       const std::filesystem::path& scene_file) {
  return std::make_unique<SessionRecorder>(path, world.content_hash(), 8192,
                                           SessionRecorder::Overflow::kDrop, scene_file);
}

void finish_session_recording(SessionRecorder& recorder, SessionSummary& summary) {
  try {
    recorder.close();
  } catch (const Error& e) {  // a full disk: the summary and the JSON are still written
    if (summary.recording_error.empty()) {
      summary.recording_error = e.what();
    }
  }
}

std::optional<FemSummary> fem_summary(const World& world) {
  const FemCoupling* fem = world.fem();
  if (fem == nullptr) {
    return std::nullopt;
  }
  FemSummary s;
  const FemCouplingStats& st = fem->stats();
  s.updates = st.updates;
  s.adopted = fem->adopted();
  s.late_adopted = fem->late_adopted();
  s.skipped_launches = st.skipped_launches;
  s.period_steps = fem->period_steps();
  if (!st.update_ms.empty()) {
    std::vector<double> ms = st.update_ms;
    s.update_ms_p50 = nearest_rank_percentile(ms, 0.50);
    s.update_ms_p99 = nearest_rank_percentile(ms, 0.99);
    s.update_ms_max = *std::max_element(ms.begin(), ms.end());
  }
  for (std::size_t b = 0; b < fem->body_count(); ++b) {
    const FemBody& body = fem->body(b);
    FemSummary::Body out;
    out.name = world.description().bodies[fem->world_body(b)].name;
    out.tets = body.tet_count();
    out.nodes = body.node_count();
    out.elasticity = std::string(to_string(body.options().elasticity));
    for (std::size_t i = 0; i < body.node_count(); ++i) {
      out.final_max_displacement_m = std::max(
          out.final_max_displacement_m, body.displacement(static_cast<std::uint32_t>(i)).norm());
    }
    s.bodies.push_back(std::move(out));
  }
  s.failures = world.state().fem_failures;
  return s;
}

std::vector<StiffnessClamp> stiffness_clamps(const World& world) {
  const double max_k = world.model().options().max_stiffness_n_per_m;
  const WorldDescription& d = world.description();
  std::vector<bool> used(d.materials.size(), false);
  for (const SegmentModel& seg : world.model().segments()) {
    if (seg.material < used.size()) {
      used[seg.material] = true;
    }
  }
  std::vector<StiffnessClamp> clamps;
  for (std::size_t m = 0; m < d.materials.size(); ++m) {
    const double k = d.materials[m].contact.stiffness_n_per_m;
    if (used[m] && k > max_k) {
      clamps.push_back({d.materials[m].name, k, max_k});
    }
  }
  return clamps;
}

bool TeleopSummary::placed() const {
  return nonfinite_ball_steps == 0 && grasped && release_time_s >= 0.0 &&
         (!target_error_m || *target_error_m <= 0.005);
}

std::string format_session_summary(const SessionSummary& s) {
  std::ostringstream out;
  char line[256];
  std::snprintf(line, sizeof line, "%zu steps, %.3f s simulated in %.3f s wall (%.1fx real time)\n",
                s.steps, s.simulated_s, s.wall_s, s.wall_s > 0.0 ? s.simulated_s / s.wall_s : 0.0);
  out << line;
  std::snprintf(line, sizeof line,
                "step cost: p50 %.2f us, p99 %.2f us, max %.1f us, mean %.2f us\n", s.step_us.p50,
                s.step_us.p99, s.step_us.max, s.step_us.mean);
  out << line;
  if (!s.stiffness_clamps.empty()) {
    const auto n_per_m = [&line](double k) {
      std::snprintf(line, sizeof line, "%.6g N/m", k);
      return std::string(line);
    };
    out << "stiffness clamped to the device's rated "
        << n_per_m(s.stiffness_clamps.front().clamped_n_per_m) << ": material";
    for (std::size_t i = 0; i < s.stiffness_clamps.size(); ++i) {
      const StiffnessClamp& c = s.stiffness_clamps[i];
      out << (i == 0 ? " '" : ", '") << c.material << "' " << n_per_m(c.stiffness_n_per_m);
    }
    out << "\n";
  }
  for (const ToolSummary& t : s.tools) {
    std::snprintf(line, sizeof line,
                  "tool %-14s peak %.3f N, mean %.3f N while touching (%zu steps in contact)\n",
                  t.name.c_str(), t.peak_force_n, t.mean_force_n, t.contact_steps);
    out << line;
  }
  if (s.teleop && !s.teleop->has_ball) {
    const TeleopSummary& t = *s.teleop;
    std::snprintf(
        line, sizeof line,
        "slave tool   peak force %.3f N (what the master's hand feels, before the scale); "
        "master peak joint torque %.3f N m\nslave        largest tip error while "
        "tracking %.3f mm; held to its joint limits on %zu steps\n",
        t.peak_tool_force_n, t.peak_master_torque_nm, t.max_slave_tracking_error_m * 1e3,
        t.slave_limited_steps);
    out << line;
  } else if (s.teleop) {
    const TeleopSummary& t = *s.teleop;
    if (t.grasped) {
      std::snprintf(
          line, sizeof line,
          "grasp        achieved at %.3f s, peak grasp force %.2f N, ball lifted %.1f mm\n",
          t.grasp_time_s, t.peak_grasp_force_n, t.ball_lift_m * 1e3);
    } else {
      std::snprintf(line, sizeof line, "grasp        never achieved\n");
    }
    out << line;
    if (t.release_time_s >= 0.0) {
      std::snprintf(line, sizeof line, "release      at %.3f s\n", t.release_time_s);
      out << line;
    }
    std::snprintf(line, sizeof line, "ball         ends at (%.4f, %.4f, %.4f) m",
                  t.ball_final_world.x(), t.ball_final_world.y(), t.ball_final_world.z());
    out << line;
    if (t.target_error_m) {
      std::snprintf(line, sizeof line, ", %.2f mm from the target spot", *t.target_error_m * 1e3);
      out << line;
    }
    std::snprintf(line, sizeof line,
                  "\nsheet        deepest dent %.3f mm\nslave        largest tip error while "
                  "tracking %.3f mm; held to its joint limits on %zu steps\n",
                  t.max_sheet_deflection_m * 1e3, t.max_slave_tracking_error_m * 1e3,
                  t.slave_limited_steps);
    out << line;
  }
  if (s.teleop) {
    const TeleopSummary& t = *s.teleop;
    if (t.slave_collision_steps == 0) {
      out << (t.has_ball
                  ? "slave collisions none (no link, palm or pad inside the floor or the sheet)\n"
                  : "slave collisions none (no link, palm or pad inside a body it cannot push)\n");
    } else {
      std::snprintf(line, sizeof line,
                    "slave collisions in %zu steps, first at %.3f s:", t.slave_collision_steps,
                    t.first_slave_collision_s);
      out << line;
      for (std::size_t i = 0; i < t.slave_collision_bodies.size(); ++i) {
        out << (i == 0 ? " " : ", ") << t.slave_collision_bodies[i];
      }
      out << " (the real robot would hit them)\n";
    }
  }
  for (const BodySummary& b : s.bodies) {
    std::snprintf(line, sizeof line,
                  "body %-8s from (%.1f, %.1f, %.1f) mm to (%.1f, %.1f, %.1f) mm, rose %.1f mm; "
                  "ends at %.1f mm/s",
                  b.name.c_str(), b.start_world.x() * 1e3, b.start_world.y() * 1e3,
                  b.start_world.z() * 1e3, b.final_world.x() * 1e3, b.final_world.y() * 1e3,
                  b.final_world.z() * 1e3, b.max_rise_m * 1e3, b.final_speed_m_per_s * 1e3);
    out << line;
    std::string on;
    for (const std::string& other : b.touching_at_end) {
      on += (on.empty() ? "" : ", ") + other;
    }
    out << (on.empty() ? ", touching nothing" : ", on " + on);
    if (b.nonfinite_steps > 0) {
      out << "; NON-FINITE in " << b.nonfinite_steps << " steps";
    }
    out << "\n";
  }
  if (s.fem) {
    for (const FemSummary::Body& b : s.fem->bodies) {
      std::snprintf(line, sizeof line,
                    "fem   %-7s %zu tets, %zu nodes, %s; largest displacement at the end %.2f mm\n",
                    b.name.c_str(), b.tets, b.nodes, b.elasticity.c_str(),
                    b.final_max_displacement_m * 1e3);
      out << line;
    }
    std::snprintf(line, sizeof line,
                  "fem   %llu updates (every %llu steps), %llu adopted, %llu late; update p50 %.2f "
                  "ms, p99 %.2f ms, max %.2f ms\n",
                  static_cast<unsigned long long>(s.fem->updates),
                  static_cast<unsigned long long>(s.fem->period_steps),
                  static_cast<unsigned long long>(s.fem->adopted),
                  static_cast<unsigned long long>(s.fem->late_adopted), s.fem->update_ms_p50,
                  s.fem->update_ms_p99, s.fem->update_ms_max);
    out << line;
    if (s.fem->failures > 0) {
      out << "fem   FAILED " << s.fem->failures << " update(s): " << s.fem->error << "\n";
    }
  }
  for (const SheetSummary& sh : s.sheets) {
    std::snprintf(line, sizeof line, "sheet %-7s deepest dent %.2f mm, %.2f mm at the end\n",
                  sh.name.c_str(), sh.max_depth_m * 1e3, sh.final_depth_m * 1e3);
    out << line;
  }
  if (!s.segments.empty()) {
    out << "segments touched by tools (tool-steps in contact, peak force, largest deflection):\n";
  }
  std::size_t untouched = 0;
  for (const SegmentSummary& g : s.segments) {
    if (g.contacts == 0 && g.max_deflection_m == 0.0) {
      ++untouched;
      continue;
    }
    std::snprintf(line, sizeof line, "  %-34s %7zu  %7.3f N  %6.2f mm\n",
                  (g.body + "/" + g.name).c_str(), g.contacts, g.peak_force_n,
                  g.max_deflection_m * 1e3);
    out << line;
  }
  if (untouched > 0) {
    out << "  (" << untouched << " segment(s) never touched by a tool)\n";
  }
  std::snprintf(line, sizeof line,
                "pop-throughs: %zu (deepest proxy sphere reach %.3f mm); force-limit violations: "
                "%zu; safety clamps: %zu cycles; non-finite commands: %zu\n",
                s.pop_throughs, s.max_proxy_penetration_m * 1e3, s.max_force_limit_violations,
                s.clamped_cycles, s.nonfinite_commands);
  out << line;
  if (s.started_inside > 0) {
    out << "started inside: " << s.started_inside << " time(s), first " << s.started_inside_first
        << " (placed inside a body, not a pop-through: no force until it leaves)\n";
  }
  if (s.dropped_contacts > 0) {
    out << "contacts dropped (buffer full): " << s.dropped_contacts << "\n";
  }
  if (s.recorded_frames > 0 || s.recording_dropped_frames > 0) {
    out << "recorded frames: " << s.recorded_frames << " (dropped " << s.recording_dropped_frames
        << ")\n";
  }
  if (!s.recording_error.empty()) {
    out << "recording STOPPED early: " << s.recording_error << "\n";
  }
  if (s.realtime) {
    out << format_realtime_summary(*s.realtime);
  }
  return out.str();
}

}  // namespace hapsim
