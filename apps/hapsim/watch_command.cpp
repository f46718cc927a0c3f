// `hapsim watch`: a viewer of a served world with no window (docs/architecture.md#distribution).
// It joins a session like `hapsim view --connect` (SceneInfo, the same scene built here, the hash
// checked), decodes every ViewState it gets into the world's snapshot, and reports what it saw:
// how many views and how fast, the largest force and dent. --snapshot draws, offscreen, the view
// at the largest force it saw. For headless machines, tests, and the network benchmark's viewers.
#include "commands.h"
#include "dds_options.h"
#include "json_output.h"
#include "session_join.h"
#include "snapshot_view.h"
#include "stop_signal.h"

#include "hapsim/core/error.h"
#include "hapsim/net/dds_domain.h"
#include "hapsim/net/loaned_reader.h"
#include "hapsim/net/participant.h"
#include "hapsim/net/served_scene.h"
#include "hapsim/net/view_state_codec.h"
#include "hapsim/render/snapshot_writer.h"
#include "hapsim/render/world_scene.h"

#include <nlohmann/json.hpp>

#include <atomic>
#include <chrono>
#include <cinttypes>
#include <cmath>
#include <csignal>
#include <cstdio>
#include <limits>
#include <memory>
#include <optional>
#include <string>
#include <thread>

namespace hapsim::app {
namespace {

struct WatchArgs {
  DdsOptions dds;
  std::string data_dir;
  double duration_s = std::numeric_limits<double>::quiet_NaN();  // NaN: until stopped
  double wait_s = 20.0;
  std::string snapshot_path;
  std::string view;
  std::string camera;
  std::string json_path;
};

double peak_tool_force_n(const WorldSnapshot& s) {
  double peak = 0.0;
  for (const double f : s.tool_force_n) {
    peak = std::max(peak, f);
  }
  return peak;
}

void watch(const WatchArgs& args, JsonOutput& json_out) {
  using Clock = std::chrono::steady_clock;
  SessionJoin session(args.dds, args.wait_s);
  const net::SceneInfoSample* info = &session.info();
  net::LoanedReader<hapsim_msg_ViewState>& views_in = session.views();
  const std::atomic<bool>& stop = session.stop();
  const RunSetup setup = net::build_served_scene(*info, DeviceChoice::external(), args.data_dir);
  const World& world = *setup.world;
  const std::optional<OrbitCamera> chosen =
      chosen_snapshot_camera(setup.scene, args.view, args.camera);
  std::printf("watching     %s in session '%s' (%s)\n", info->scene_file.c_str(),
              args.dds.session.c_str(), session.domain().config().c_str());
  std::fflush(stdout);

  WorldSnapshot snapshot = make_world_snapshot(world);  // a rig's part too: view states carry it
  std::optional<WorldSnapshot> at_peak;
  net::ViewStateDecoder decoder(world);
  std::uint64_t views = 0;
  std::uint64_t refused = 0;
  std::string last_refusal;
  double peak_force_n = 0.0;
  // A rig's grasp (its pads' mean push on the ball), and the larger of the two: the view drawn.
  double peak_grasp_force_n = 0.0;
  double peak_felt_n = 0.0;
  double max_deflection_m = 0.0;
  std::uint64_t first_cycle = 0;
  std::uint64_t last_cycle = 0;
  const auto start = Clock::now();
  const auto end = std::isnan(args.duration_s)
                       ? Clock::time_point::max()
                       : start + std::chrono::duration_cast<Clock::duration>(
                                     std::chrono::duration<double>(args.duration_s));
  while (Clock::now() < end && !stop.load(std::memory_order_relaxed)) {
    views_in.take([&](const hapsim_msg_ViewState& m) {
      std::string why;
      if (!decoder.decode(m, info->scene_hash, snapshot, why)) {
        ++refused;
        last_refusal = why;
        return;
      }
      first_cycle = views == 0 ? snapshot.cycle : first_cycle;
      last_cycle = snapshot.cycle;
      ++views;
      for (const double d : snapshot.deflection_m) {
        max_deflection_m = std::max(max_deflection_m, d);
      }
      const double force_n = peak_tool_force_n(snapshot);
      const double grasp_n = snapshot.teleop ? snapshot.teleop->grasp_force_n : 0.0;
      peak_force_n = std::max(peak_force_n, force_n);
      peak_grasp_force_n = std::max(peak_grasp_force_n, grasp_n);
      if (std::max(force_n, grasp_n) > peak_felt_n || !at_peak) {
        peak_felt_n = std::max(peak_felt_n, std::max(force_n, grasp_n));
        at_peak = snapshot;  // a copy now and then, off any haptic path
      }
    });
    std::this_thread::sleep_for(std::chrono::milliseconds(2));
  }
  const double wall_s = std::chrono::duration<double>(Clock::now() - start).count();
  const double rate_hz = wall_s > 0.0 ? static_cast<double>(views) / wall_s : 0.0;
  std::printf("views        %" PRIu64 " in %.2f s (%.1f per second), %" PRIu64 " refused%s%s\n",
              views, wall_s, rate_hz, refused, refused > 0 ? ": " : "", last_refusal.c_str());
  std::printf(
      "saw          peak tool force %.3f N, largest deflection %.2f mm, simulation "
      "cycles %" PRIu64 " to %" PRIu64 "\n",
      peak_force_n, max_deflection_m * 1e3, first_cycle, last_cycle);
  if (snapshot.teleop) {
    std::printf("saw          the rig's peak grasp %.3f N\n", peak_grasp_force_n);
  }
  // The snapshot's failure is said after the JSON, which records it: a full disk must not cost
  // the run's numbers.
  std::string snapshot_error;
  if (!args.snapshot_path.empty()) {
    if (!at_peak) {
      snapshot_error = "--snapshot: no view arrived to draw";
    } else {
      try {
        WorldScene scene(world);
        scene.update(*at_peak);
        SnapshotWriter writer(1280, 720);
        const OrbitCamera camera =
            chosen.value_or(framed_camera(scene.rest_bounds_world(), 1280.0 / 720.0,
                                          snapshot_yaw_rad(world), snapshot_pitch_rad(world)));
        writer.write_png(scene.scene(), camera, args.snapshot_path);
        std::printf("snapshot     %s (the view at the largest force, %.3f N, t = %.3f s)\n",
                    args.snapshot_path.c_str(), peak_felt_n, at_peak->time_s);
      } catch (const Error& e) {
        snapshot_error = "--snapshot " + std::string(e.what());  // e names the path
      }
    }
  }
  if (json_out) {
    nlohmann::json j;
    j["session"] = args.dds.session;
    j["scene"] = info->scene_file;
    j["views"] = views;
    j["refused"] = refused;
    j["wall_s"] = wall_s;
    j["views_per_s"] = rate_hz;
    j["peak_force_n"] = peak_force_n;
    if (snapshot.teleop) {
      j["peak_grasp_force_n"] = peak_grasp_force_n;
    }
    j["max_deflection_m"] = max_deflection_m;
    j["cycles"] = {first_cycle, last_cycle};
    if (*stop_signal_name() != '\0') {
      j["stopped_by"] = stop_signal_name();
    }
    if (!snapshot_error.empty()) {
      j["snapshot_error"] = snapshot_error;
    }
    j["ok"] = views > 0 && snapshot_error.empty();
    json_out.write(j);
  }
  if (!snapshot_error.empty()) {
    throw CommandError(snapshot_error);
  }
  if (views == 0) {
    std::printf("FAILED: no view arrived\n");
    exit_status() = 1;
  }
  exit_status() = with_signal_status(exit_status());
}

void watch(const WatchArgs& args) {
  JsonOutput json_out(args.json_path);
  with_failure_json(json_out, [&] { watch(args, json_out); });
}

}  // namespace

void add_watch_command(CLI::App& app) {
  auto args = std::make_shared<WatchArgs>();
  CLI::App* cmd = app.add_subcommand(
      "watch",
      "A viewer of a served world with no window: report what the simulation host serves "
      "(hapsim serve), and draw it offscreen with --snapshot");
  add_dds_options(cmd, args->dds, net::SecurityRole::kViewer);
  cmd->add_option("--data", args->data_dir, "The scene's data folder (default: the host's)");
  cmd->add_option("--duration", args->duration_s, "Seconds to watch (default: until stopped)")
      ->check(positive_seconds());
  cmd->add_option("--wait", args->wait_s, "Seconds to wait for a simulation host (default 20)")
      ->check(positive_seconds());
  cmd->add_option("--snapshot", args->snapshot_path,
                  "Write the view at the largest force seen to FILE.png (offscreen)");
  cmd->add_option("--view", args->view, "Snapshot from the served scene's named view NAME");
  cmd->add_option("--camera", args->camera,
                  "Snapshot from EX,EY,EZ,TX,TY,TZ,FOV: eye and target (world, m) and vertical "
                  "field of view (degrees)");
  cmd->add_option("--json", args->json_path, "Write what was seen as JSON");
  cmd->callback([args] {
    (void)net::session_partition(args->dds.session);
    if (args->snapshot_path.empty() && (!args->view.empty() || !args->camera.empty())) {
      throw CommandError(std::string(args->view.empty() ? "--camera" : "--view") +
                         ": only with --snapshot FILE.png");
    }
    (void)chosen_snapshot_camera({}, "", args->camera);  // a bad --camera fails before waiting
    watch(*args);
  });
}

}  // namespace hapsim::app
