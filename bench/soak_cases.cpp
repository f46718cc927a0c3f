#include "bench/soak_cases.h"

#include "hapsim/core/error.h"
#include "hapsim/core/statistics.h"
#include "hapsim/core/stopwatch.h"
#include "hapsim/scene/run_setup.h"
#include "hapsim/scene/scene_file.h"
#include "hapsim/world/world.h"

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <sstream>

namespace hapsim::bench {
namespace {

// Every channel a command carries: the tip force, the finger forces, the joint torques.
constexpr std::size_t kChannels = 3 + kMaxFingers + kMaxDeviceJoints;
using Channels = std::array<double, kChannels>;

Channels channels(const DeviceCommand& c) {
  Channels out{};
  for (int i = 0; i < 3; ++i) {
    out[i] = c.force_world_n[i];
  }
  for (int i = 0; i < kMaxFingers; ++i) {
    out[3 + i] = c.finger_force_n[i];
  }
  for (int i = 0; i < kMaxDeviceJoints; ++i) {
    out[3 + kMaxFingers + i] = c.joint_torque_nm[i];
  }
  return out;
}

}  // namespace

ProcessMemory process_memory() {
  std::ifstream in("/proc/self/status");
  ProcessMemory m;
  std::string line;
  while (std::getline(in, line)) {
    const auto kb = [&line](const char* key) {
      return static_cast<std::size_t>(std::strtoull(line.c_str() + std::strlen(key), nullptr, 10));
    };
    if (line.rfind("VmHWM:", 0) == 0) {
      m.peak_rss_bytes = kb("VmHWM:") * 1024;
    } else if (line.rfind("VmRSS:", 0) == 0) {
      m.rss_bytes = kb("VmRSS:") * 1024;
    }
  }
  return m;
}

SoakResult run_soak(const SoakOptions& options) {
  const SceneDescription scene = load_scene(options.scene);
  RunSetup setup = make_run_setup(scene, DeviceChoice::scene_script());
  if (!setup.device || setup.duration_s <= 0.0) {
    throw Error(options.scene.string(), "the soak needs a scene with a scripted device");
  }
  const double dt = scene.run.dt_s > 0.0 ? scene.run.dt_s : 1e-3;
  const auto script_steps = static_cast<std::size_t>(std::llround(setup.duration_s / dt));
  const auto total_steps = static_cast<std::size_t>(std::llround(options.duration_s / dt));
  const auto minute_steps = static_cast<std::size_t>(std::llround(60.0 / dt));

  SoakResult result;
  result.scene = options.scene.filename().string();
  result.script_s = setup.duration_s;
  std::vector<Channels> first(script_steps);
  std::vector<Channels> second(script_steps);
  std::vector<double> step_us;
  step_us.reserve(minute_steps);
  double rep_drift = 0.0;
  const Stopwatch wall;
  using Clock = std::chrono::steady_clock;
  std::size_t steps = 0;
  for (std::size_t k = 0; k < total_steps; ++k) {
    if (options.stop != nullptr && options.stop->load(std::memory_order_relaxed)) {
      result.stopped = true;
      if (!step_us.empty()) {  // the partial minute still counts
        const SampleSummary s = summarize_samples(step_us);
        const ProcessMemory memory = process_memory();
        result.minutes.push_back({s.p50, s.p99, s.max, memory.peak_rss_bytes, memory.rss_bytes});
      }
      break;
    }
    steps = k + 1;
    const std::size_t in_script = k % script_steps;
    const std::size_t rep = k / script_steps;
    if (in_script == 0) {
      if (rep > 0) {
        result.last_force_drift_n = rep_drift;
      }
      rep_drift = 0.0;
      result.repetitions = rep + 1;
      if (options.reset_between && rep > 0) {
        setup.world->reset();
      }
    }
    const DeviceInput input = setup.device->read(static_cast<double>(in_script) * dt);
    const auto t0 = Clock::now();
    const StepResult& step = setup.world->step(input, dt);
    const auto t1 = Clock::now();
    step_us.push_back(std::chrono::duration<double, std::micro>(t1 - t0).count());
    const Channels c = channels(step.command);
    if (rep == 0) {
      first[in_script] = c;
      result.peak_force_n = std::max(result.peak_force_n, step.command.force_world_n.norm());
      for (int f = 0; f < kMaxFingers; ++f) {
        result.peak_force_n = std::max(result.peak_force_n, step.command.finger_force_n[f]);
      }
    } else {
      if (rep == 1) {
        second[in_script] = c;
      }
      for (std::size_t i = 0; i < kChannels; ++i) {
        const double d = std::abs(c[i] - first[in_script][i]);
        rep_drift = std::max(rep_drift, std::isfinite(d) ? d : HUGE_VAL);
        if (rep >= 2) {
          const double d2 = std::abs(c[i] - second[in_script][i]);
          result.max_drift_from_second_n =
              std::max(result.max_drift_from_second_n, std::isfinite(d2) ? d2 : HUGE_VAL);
        }
      }
      result.max_force_drift_n = std::max(result.max_force_drift_n, rep_drift);
    }
    if (step_us.size() == minute_steps || k + 1 == total_steps) {
      const SampleSummary s = summarize_samples(step_us);
      const ProcessMemory memory = process_memory();
      result.minutes.push_back({s.p50, s.p99, s.max, memory.peak_rss_bytes, memory.rss_bytes});
      step_us.clear();
      report_progress(options.progress, result.scene,
                      static_cast<double>(k + 1) / static_cast<double>(total_steps));
    }
  }
  if (!result.stopped && result.repetitions > 1 && total_steps % script_steps == 0) {
    result.last_force_drift_n = rep_drift;
  }
  result.steps = steps;
  result.wall_s = wall.elapsed_s();
  return result;
}

std::string format_soak(const SoakResult& r) {
  std::ostringstream out;
  char line[256];
  std::snprintf(line, sizeof line,
                "%s: %.0f s simulated in %.1f s wall (%.0fx), the %.2f s script %zu times\n",
                r.scene.c_str(), static_cast<double>(r.steps) * 1e-3, r.wall_s,
                static_cast<double>(r.steps) * 1e-3 / r.wall_s, r.script_s, r.repetitions);
  out << line;
  std::snprintf(line, sizeof line, "  %-8s %9s %9s %9s %12s %10s\n", "minute", "p50 us", "p99 us",
                "max us", "peak RSS MB", "RSS MB");
  out << line;
  for (std::size_t i = 0; i < r.minutes.size(); ++i) {
    // Every minute for a short soak; the first, every tenth and the last for an hour.
    if (r.minutes.size() > 12 && i != 0 && (i + 1) % 10 != 0 && i + 1 != r.minutes.size()) {
      continue;
    }
    const SoakMinute& m = r.minutes[i];
    std::snprintf(line, sizeof line, "  %-8zu %9.2f %9.2f %9.1f %12.1f %10.1f\n", i + 1, m.p50_us,
                  m.p99_us, m.max_us, static_cast<double>(m.peak_rss_bytes) / 1048576.0,
                  static_cast<double>(m.rss_bytes) / 1048576.0);
    out << line;
  }
  if (!r.minutes.empty()) {
    const SoakMinute& a = r.minutes.front();
    const SoakMinute& b = r.minutes.back();
    std::snprintf(
        line, sizeof line,
        "  peak RSS %+.2f MB from minute 1 to minute %zu; p50 %.2f -> %.2f us, p99 "
        "%.2f -> %.2f us\n",
        (static_cast<double>(b.peak_rss_bytes) - static_cast<double>(a.peak_rss_bytes)) / 1048576.0,
        r.minutes.size(), a.p50_us, b.p50_us, a.p99_us, b.p99_us);
    out << line;
  }
  std::snprintf(line, sizeof line,
                "  force drift against the first repetition: max %.3g N over all, %.3g N in the "
                "last (peak force %.2f N); against the second: max %.3g N\n",
                r.max_force_drift_n, r.last_force_drift_n, r.peak_force_n,
                r.max_drift_from_second_n);
  out << line;
  return out.str();
}

nlohmann::json soak_to_json(const SoakResult& r) {
  nlohmann::json minutes = nlohmann::json::array();
  for (const SoakMinute& m : r.minutes) {
    minutes.push_back({{"p50_us", m.p50_us},
                       {"p99_us", m.p99_us},
                       {"max_us", m.max_us},
                       {"peak_rss_bytes", m.peak_rss_bytes},
                       {"rss_bytes", m.rss_bytes}});
  }
  return {{"scene", r.scene},
          {"script_s", r.script_s},
          {"repetitions", r.repetitions},
          {"steps", r.steps},
          {"stopped_early", r.stopped},
          {"wall_s", r.wall_s},
          {"max_force_drift_n", r.max_force_drift_n},
          {"last_force_drift_n", r.last_force_drift_n},
          {"max_drift_from_second_n", r.max_drift_from_second_n},
          {"peak_force_n", r.peak_force_n},
          {"minutes", minutes}};
}

}  // namespace hapsim::bench
