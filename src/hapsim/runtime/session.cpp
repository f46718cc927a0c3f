#include "hapsim/runtime/session.h"

#include "hapsim/collision/mesh_bvh.h"
#include "hapsim/core/error.h"
#include "hapsim/device/force_safety.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <ctime>
#include <memory>
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

void sleep_until(const timespec& deadline) {
  while (clock_nanosleep(CLOCK_MONOTONIC, TIMER_ABSTIME, &deadline, nullptr) != 0) {
    // EINTR: sleep again to the same absolute deadline.
  }
}

timespec add_ns(timespec t, long long ns) {
  constexpr long long kNsPerS = 1'000'000'000LL;
  long long total = static_cast<long long>(t.tv_nsec) + ns;
  t.tv_sec += static_cast<time_t>(total / kNsPerS);
  total %= kNsPerS;
  t.tv_nsec = static_cast<long>(total);
  return t;
}

double to_s(const timespec& t) {
  return static_cast<double>(t.tv_sec) + 1e-9 * static_cast<double>(t.tv_nsec);
}

RecordedFrame make_frame(std::uint64_t cycle, const DeviceInput& input,
                         const DeviceCommand& command, const StepResult& result) {
  RecordedFrame frame;
  frame.cycle_index = cycle;
  frame.input = input;
  frame.command = command;
  const std::size_t n =
      std::min<std::size_t>(result.contacts.size(), static_cast<std::size_t>(kMaxRecordedContacts));
  frame.contact_count = static_cast<std::int32_t>(n);
  for (std::size_t i = 0; i < n; ++i) {
    const WorldContact& c = result.contacts[i];
    RecordedContact& r = frame.contacts[i];
    r.tool_index = c.tool;
    r.body_index = c.body;
    r.segment_index = c.segment;
    r.point_world = c.point_world;
    r.normal_world = c.normal_world;
    r.depth_m = c.depth_m;
    r.force_n = c.force_n;
  }
  return frame;
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
  if (command.force_world_n.norm() > profile.max_force_n) {
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

StepTimingUs step_timing(std::vector<double>& samples_us) {
  StepTimingUs t;
  if (samples_us.empty()) {
    return t;
  }
  std::sort(samples_us.begin(), samples_us.end());
  // Nearest-rank percentiles: a value that was actually measured.
  const auto rank = [&](double q) {
    const auto n = samples_us.size();
    const auto k = static_cast<std::size_t>(std::ceil(q * static_cast<double>(n)));
    return samples_us[std::clamp<std::size_t>(k, 1, n) - 1];
  };
  t.p50 = rank(0.50);
  t.p99 = rank(0.99);
  t.max = samples_us.back();
  double sum = 0.0;
  for (double v : samples_us) {
    sum += v;
  }
  t.mean = sum / static_cast<double>(samples_us.size());
  return t;
}

SessionSummary run_session(World& world, Device& device, const SessionOptions& options) {
  if (!(options.duration_s > 0.0) || !std::isfinite(options.duration_s)) {
    throw Error("session", "duration must be a finite number of seconds > 0, got " +
                               std::to_string(options.duration_s));
  }
  if (!(options.dt_s > 0.0) || !(options.dt_s <= 0.1)) {
    throw Error("session", "dt must be in (0, 0.1] s, got " + std::to_string(options.dt_s));
  }
  const auto steps = static_cast<std::size_t>(std::llround(options.duration_s / options.dt_s));
  const WorldDescription& desc = world.description();

  SessionSummary summary;
  summary.tools.resize(desc.tools.size());
  std::vector<double> force_sum(desc.tools.size(), 0.0);
  for (std::size_t t = 0; t < desc.tools.size(); ++t) {
    summary.tools[t].name = desc.tools[t].name;
  }
  summary.segments.resize(world.flat_segment_count());
  for (std::size_t b = 0; b < desc.bodies.size(); ++b) {
    for (std::size_t s = 0; s < desc.bodies[b].segments.size(); ++s) {
      SegmentSummary& seg = summary.segments[world.flat_segment(b, s)];
      seg.body = desc.bodies[b].name;
      seg.name = desc.bodies[b].segments[s].name;
    }
  }
  const std::vector<ProxyCheck> checks =
      options.check_pop_through ? make_proxy_checks(world) : std::vector<ProxyCheck>{};

  ForceWatchdog watchdog(device.profile());
  std::vector<double> cost_us;
  cost_us.reserve(steps);
  // Per-segment touch flags of one step, so a tool-step counts once per segment.
  std::vector<std::uint8_t> touched(summary.segments.size() * desc.tools.size(), 0);

  const auto wall_start = std::chrono::steady_clock::now();
  timespec deadline{};
  clock_gettime(CLOCK_MONOTONIC, &deadline);
  const long long period_ns = std::llround(options.dt_s * 1e9);
  const std::size_t progress_every = std::max<std::size_t>(1, steps / 100);

  for (std::size_t i = 0; i < steps; ++i) {
    const double t_s = static_cast<double>(i) * options.dt_s;
    if (options.realtime) {
      deadline = add_ns(deadline, period_ns);
      sleep_until(deadline);
    }
    // The timed haptic cycle: read, step (collision, force, deformation), safety, write.
    const auto c0 = std::chrono::steady_clock::now();
    const DeviceInput input = device.read(t_s);
    const StepResult& result = world.step(input, options.dt_s);
    const bool healthy = input.healthy && device.status().health == DeviceHealth::kConnected;
    const DeviceCommand out = watchdog.update(t_s, &result.command, healthy);
    device.write(out);
    const auto c1 = std::chrono::steady_clock::now();
    cost_us.push_back(std::chrono::duration<double, std::micro>(c1 - c0).count());

    if (options.realtime) {
      timespec now{};
      clock_gettime(CLOCK_MONOTONIC, &now);
      if (to_s(now) - to_s(deadline) > options.dt_s) {
        ++summary.missed_deadlines;
        deadline = now;  // do not try to catch up with a burst of cycles
      }
    }

    // Bookkeeping (outside the timed cycle).
    if (exceeds_limits(out, device.profile())) {
      ++summary.max_force_limit_violations;
    }
    summary.peak_command_force_n = std::max(summary.peak_command_force_n, command_peak_n(out));
    summary.dropped_contacts += static_cast<std::size_t>(std::max(0, result.dropped_contacts));
    std::fill(touched.begin(), touched.end(), std::uint8_t{0});
    for (const WorldContact& c : result.contacts) {
      const std::size_t flat =
          world.flat_segment(static_cast<std::size_t>(c.body), static_cast<std::size_t>(c.segment));
      SegmentSummary& seg = summary.segments[flat];
      seg.peak_force_n = std::max(seg.peak_force_n, c.force_n);
      std::uint8_t& flag = touched[flat * desc.tools.size() + static_cast<std::size_t>(c.tool)];
      if (flag == 0) {
        flag = 1;
        ++seg.contacts;
      }
    }
    // What the device renders of the tools' summed tip force (the safety layer may scale it).
    const double tip_n = result.command.force_world_n.norm();
    const double tip_scale = tip_n > 0.0 ? out.force_world_n.norm() / tip_n : 0.0;
    for (std::size_t t = 0; t < result.tools.size() && t < summary.tools.size(); ++t) {
      const ToolState& tool = result.tools[t];
      ToolSummary& ts = summary.tools[t];
      const int finger = desc.tools[t].finger;
      const double f = finger >= 0 && finger < out.finger_count
                           ? out.finger_force_n[static_cast<std::size_t>(finger)]
                           : tool.force_world_n.norm() * tip_scale;
      ts.peak_force_n = std::max(ts.peak_force_n, f);
      if (tool.contact_count > 0) {
        ++ts.contact_steps;
        force_sum[t] += f;
      }
      for (const ProxyCheck& c : checks) {
        const Vec3 p_body = c.X_body_world * tool.proxy_world;
        const double r = desc.tools[t].radius_m;
        if (c.bounds_body.exteriorDistance(p_body) > r) {
          continue;
        }
        const SurfacePoint sp = c.bvh->closest_point(p_body);
        summary.max_proxy_penetration_m =
            std::max(summary.max_proxy_penetration_m, r - sp.signed_distance);
        if (sp.signed_distance < 0.0) {
          ++summary.pop_throughs;
        }
      }
    }
    for (std::size_t b = 0; b < desc.bodies.size(); ++b) {
      if (desc.bodies[b].kind != BodyKind::kDeformable) {
        continue;
      }
      for (std::size_t s = 0; s < desc.bodies[b].segments.size(); ++s) {
        SegmentSummary& seg = summary.segments[world.flat_segment(b, s)];
        seg.max_deflection_m = std::max(seg.max_deflection_m, world.current_deflection_m(b, s));
      }
    }
    if (options.recorder != nullptr) {
      if (!options.recorder->record(make_frame(i, input, out, result))) {
        ++summary.recording_dropped_frames;
      } else {
        ++summary.recorded_frames;
      }
      if (!options.realtime &&
          options.recorder->frames_buffered() >= options.recorder->capacity_frames()) {
        options.recorder->flush();  // offline: the disk may be touched between cycles
      }
    }
    if ((i + 1) % progress_every == 0 || i + 1 == steps) {
      report_progress(options.progress, "run",
                      static_cast<double>(i + 1) / static_cast<double>(steps));
    }
  }
  if (options.recorder != nullptr) {
    options.recorder->flush();
  }
  summary.wall_s =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - wall_start).count();
  summary.steps = steps;
  summary.simulated_s = static_cast<double>(steps) * options.dt_s;
  for (std::size_t t = 0; t < summary.tools.size(); ++t) {
    ToolSummary& ts = summary.tools[t];
    ts.mean_force_n =
        ts.contact_steps > 0 ? force_sum[t] / static_cast<double>(ts.contact_steps) : 0.0;
  }
  summary.clamped_cycles = watchdog.clamped_cycles();
  summary.nonfinite_commands = watchdog.nonfinite_count();
  summary.step_us = step_timing(cost_us);
  return summary;
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
  for (const ToolSummary& t : s.tools) {
    std::snprintf(line, sizeof line,
                  "tool %-14s peak %.3f N, mean %.3f N while touching (%zu steps in contact)\n",
                  t.name.c_str(), t.peak_force_n, t.mean_force_n, t.contact_steps);
    out << line;
  }
  out << "segments touched (tool-steps in contact, peak force, largest deflection):\n";
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
    out << "  (" << untouched << " segment(s) never touched)\n";
  }
  std::snprintf(line, sizeof line,
                "pop-throughs: %zu (deepest proxy sphere reach %.3f mm); force-limit violations: "
                "%zu; safety clamps: %zu cycles; non-finite commands: %zu\n",
                s.pop_throughs, s.max_proxy_penetration_m * 1e3, s.max_force_limit_violations,
                s.clamped_cycles, s.nonfinite_commands);
  out << line;
  if (s.dropped_contacts > 0) {
    out << "contacts dropped (buffer full): " << s.dropped_contacts << "\n";
  }
  if (s.recorded_frames > 0 || s.recording_dropped_frames > 0) {
    out << "recorded frames: " << s.recorded_frames << " (dropped " << s.recording_dropped_frames
        << ")\n";
  }
  if (s.missed_deadlines > 0) {
    out << "missed real-time deadlines: " << s.missed_deadlines << "\n";
  }
  return out.str();
}

}  // namespace hapsim
