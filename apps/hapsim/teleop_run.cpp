// `hapsim run` on a teleoperation scene (scenes/teleop.json): the master (scripted pick-and-place
// or a trajectory of master joints) drives the slave, which grasps the ball and places it on the
// sheet; the summary says whether and when it was grasped and released, how high it went, where
// it ended and how far from the target, the peak grasp force, the sheet's deepest dent and the
// step cost.
#include "teleop_run.h"

#include "commands.h"
#include "realtime_json.h"

#include "hapsim/core/device_profile.h"
#include "hapsim/core/statistics.h"
#include "hapsim/core/stopwatch.h"
#include "hapsim/device/simulated_device.h"
#include "hapsim/runtime/haptic_loop.h"
#include "hapsim/runtime/record_drain.h"
#include "hapsim/runtime/session.h"
#include "hapsim/runtime/teleop_haptic_client.h"
#include "hapsim/scene/teleop_setup.h"
#include "hapsim/world/world.h"

#include <nlohmann/json.hpp>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <optional>
#include <vector>

namespace hapsim::app {

void run_teleop(const SceneDescription& scene, const TeleopRunOptions& options) {
  if (std::isfinite(options.duration_s) && !(options.duration_s > 0.0)) {
    throw CommandError("--duration: expected a positive number of seconds");
  }
  // The world, the master's input and the slave's start (scene/teleop_setup.h); errors there
  // are hapsim::Error naming the file, printed as one line like a CommandError.
  TeleopSetup setup = make_teleop_setup(scene, options.trajectory, /*load_link_meshes=*/false);
  const Trajectory& trajectory = setup.trajectory;
  const bool has_target = setup.has_target;
  const Vec3 target = setup.target_world;
  const std::string& device_name = setup.device_name;
  const std::string& slave_name = setup.slave_name;
  World world(std::move(setup.description));
  std::printf(
      "scene        %s: teleoperation, slave %s (%d joints), ball %.0f g r %.0f mm, "
      "sheet %dx%d\n",
      scene.file.string().c_str(), slave_name.c_str(), world.rig()->slave->chain().dof(),
      world.rig()->ball.params().mass_kg * 1e3, world.rig()->ball.params().radius_m * 1e3,
      scene.teleop.sheet_nodes_per_side, scene.teleop.sheet_nodes_per_side);
  std::printf("device       %s\n", device_name.c_str());

  const double dt = scene.run.dt_s;
  double duration = trajectory.end_time_s() - trajectory.start_time_s();
  if (scene.run.duration_s > 0.0) {
    duration = scene.run.duration_s;
  }
  if (std::isfinite(options.duration_s)) {
    duration = options.duration_s;
  }
  const auto steps = static_cast<std::size_t>(std::llround(duration / dt));
  std::vector<double> step_us;
  step_us.reserve(steps);
  bool grasped = false;
  double grasp_time = -1.0;
  double release_time = -1.0;
  double lift = 0.0;
  double peak_grasp = 0.0;
  double deepest_sheet = 0.0;
  double slave_error = 0.0;
  std::size_t nonfinite = 0;
  const double start_z = world.rig()->ball.p_world().z();
  const auto account = [&](const TeleopStepResult& r, double cost_us) {
    step_us.push_back(cost_us);
    if (r.gripper.grasped_now && !grasped) {
      grasped = true;
      grasp_time = r.time_s;
    }
    if (r.gripper.released_now && grasped && release_time < 0.0) {
      release_time = r.time_s;
    }
    lift = std::max(lift, r.ball_p_world.z() - start_z);
    peak_grasp = std::max(peak_grasp, r.gripper.grasp_force_n());
    deepest_sheet = std::max(deepest_sheet, r.sheet_depth_m);
    slave_error = std::max(slave_error, r.slave.position_error_m);
    nonfinite += r.ball_p_world.allFinite() ? 0 : 1;
    const std::size_t k = step_us.size();
    if (options.progress && k % std::max<std::size_t>(steps / 100, 1) == 0) {
      options.progress(options.realtime ? "run (real time)" : "run",
                       static_cast<double>(k) / static_cast<double>(steps));
    }
  };
  std::optional<RealtimeSummary> realtime;
  const Stopwatch wall;
  if (!options.realtime) {
    for (std::size_t k = 1; k <= steps; ++k) {
      const DeviceInput in = trajectory.sample_at(trajectory.start_time_s() + k * dt);
      const Stopwatch watch;
      const TeleopStepResult& r = *world.step(in, dt).teleop;
      const double cost_us = watch.elapsed_s() * 1e6;
      if (options.after_step) {
        options.after_step(world, k);
      }
      account(r, cost_us);
    }
  } else {
    // The same cycles on the real-time haptic thread: cycle i plays the trajectory at
    // start + (i + 1)·dt as the inline loop does; every result comes back through a ring.
    const Trajectory& played = trajectory;
    SimulatedDevice device(
        device_profile("simulated"),
        [&played, dt](double t_s) { return played.sample_at(played.start_time_s() + t_s + dt); },
        static_cast<double>(steps) * dt);
    TeleopHapticClientOptions co;
    co.publish_snapshots = false;
    co.record_capacity = 4096;
    TeleopHapticClient client(world, co);
    HapticLoopOptions lo;
    lo.period_s = dt;
    lo.max_cycles = steps;
    lo.missed_period_s = 2.0 * dt;
    lo.spin_s = options.spin_s;
    HapticLoop loop(device, client, lo);
    loop.start();
    drain_until_stopped(loop, *client.records(),
                        [&](const TeleopCycleRecord& r) { account(r.result, r.cost_us); });
    loop.wait();
    realtime = realtime_summary(loop.status(), client.dropped_records());
  }
  const double wall_s = wall.elapsed_s();
  if (options.finished) {
    options.finished(world);
  }
  const Vec3 final_p = world.rig()->ball.p_world();
  const double target_error = has_target ? (final_p - target).norm() : -1.0;
  const SampleSummary cost = summarize_samples(step_us);
  const double p50 = cost.p50, p99 = cost.p99, max_us = cost.max;

  std::printf("%zu steps, %.3f s simulated in %.3f s wall\n", steps, steps * dt, wall_s);
  if (grasped) {
    std::printf("grasp        achieved at %.3f s, peak grasp force %.2f N, ball lifted %.1f mm\n",
                grasp_time, peak_grasp, lift * 1e3);
  } else {
    std::printf("grasp        never achieved\n");
  }
  if (release_time >= 0.0) {
    std::printf("release      at %.3f s\n", release_time);
  }
  std::printf("ball         ends at (%.4f, %.4f, %.4f) m", final_p.x(), final_p.y(), final_p.z());
  if (has_target) {
    std::printf(", %.2f mm from the target spot", target_error * 1e3);
  }
  std::printf("\nsheet        deepest dent %.3f mm\n", deepest_sheet * 1e3);
  std::printf("slave        largest tip error while tracking %.3f mm\n", slave_error * 1e3);
  std::printf("step cost: p50 %.2f us, p99 %.2f us, max %.1f us\n", p50, p99, max_us);
  if (realtime) {
    std::fputs(format_realtime_summary(*realtime).c_str(), stdout);
  }

  const bool ok =
      nonfinite == 0 && (!has_target || (grasped && release_time >= 0.0 && target_error <= 0.005));
  if (!ok) {
    std::printf("FAILED: the pick-and-place did not end with the ball within 5 mm of the target\n");
    exit_status() = 1;
  }
  if (!options.json_path.empty()) {
    nlohmann::json j;
    j["scene"] = scene.file.string();
    j["device"] = device_name;
    j["slave"] = slave_name;
    j["steps"] = steps;
    j["dt_s"] = dt;
    j["grasped"] = grasped;
    j["grasp_time_s"] = grasped ? nlohmann::json(grasp_time) : nlohmann::json(nullptr);
    j["release_time_s"] =
        release_time >= 0.0 ? nlohmann::json(release_time) : nlohmann::json(nullptr);
    j["ball_lift_m"] = lift;
    j["ball_final_position_m"] = {final_p.x(), final_p.y(), final_p.z()};
    j["ball_target_error_m"] = has_target ? nlohmann::json(target_error) : nlohmann::json(nullptr);
    j["peak_grasp_force_n"] = peak_grasp;
    j["max_sheet_deflection_m"] = deepest_sheet;
    j["max_slave_tracking_error_m"] = slave_error;
    j["step_us"] = {{"p50", p50}, {"p99", p99}, {"max", max_us}};
    j["wall_s"] = wall_s;
    if (realtime) {
      j["realtime"] = realtime_json(*realtime);
    }
    j["ok"] = ok;
    std::ofstream out(options.json_path);
    out << j.dump(2) << '\n';
    if (!out) {
      throw CommandError("--json " + options.json_path + ": write failed");
    }
    std::printf("wrote        %s\n", options.json_path.c_str());
  }
}

}  // namespace hapsim::app
