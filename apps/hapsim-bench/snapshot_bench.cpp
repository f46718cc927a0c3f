// `hapsim bench snapshot SCENE`: what one headless picture of a scene costs (issue 13), as `hapsim
// run --snapshot` takes it: the world stepped by the scene's own script between pictures, the
// render scene updated from it (deformed surfaces, tools), drawn offscreen (EGL, llvmpipe where
// there is no GPU; 4x multisampling by default, as run does), read back, and the PNG encoded.
// Wall time per picture (median) and the CPU time of this thread and of the rasteriser's threads.
#include "bench_commands.h"
#include "commands.h"
#include "snapshot_view.h"

#include "hapsim/core/statistics.h"
#include "hapsim/render/force_scale.h"
#include "hapsim/render/png_image.h"
#include "hapsim/render/snapshot_writer.h"
#include "hapsim/render/world_scene.h"
#include "hapsim/rig/rig_controller.h"
#include "hapsim/scene/run_setup.h"
#include "hapsim/scene/scene_file.h"
#include "hapsim/ui/render_cpu_time.h"

#include <chrono>
#include <cstdio>
#include <filesystem>
#include <memory>
#include <string>
#include <vector>

namespace hapsim::app {
namespace {

struct SnapshotBenchArgs {
  std::string scene;
  std::string data_dir;
  int frames = 30;
  int steps_between = 50;
  int samples = 4;
  std::string size = "1280x720";
  std::string png_path;
};

void run_snapshot_bench(const SnapshotBenchArgs& args) {
  int w = 0;
  int h = 0;
  if (std::sscanf(args.size.c_str(), "%dx%d", &w, &h) != 2 || w < 16 || h < 16 || w > 8192 ||
      h > 8192) {
    throw CommandError("--size " + args.size + ": expected WIDTHxHEIGHT in pixels, e.g. 1280x720");
  }
  SceneLoadOptions load;
  if (!args.data_dir.empty()) {
    load.data_dir = args.data_dir;
  }
  RunSetup setup = make_run_setup(load_scene(args.scene, load), DeviceChoice::scene_script());
  World& world = *setup.world;
  Device& device = *setup.device;
  const double dt_s = setup.scene.run.dt_s;

  SnapshotWriter writer(w, h, args.samples);
  WorldSceneOptions o;
  o.force_full_scale_n = force_display_scale_n(
      world.description(), rig_state(world) != nullptr
                               ? rig_description(world.description())->gripper.max_force_n
                               : device_rated_force_n(*setup.profile));
  WorldScene drawn(world, o);
  const OrbitCamera camera = framed_camera(drawn.rest_bounds_world(), static_cast<double>(w) / h,
                                           snapshot_yaw_rad(world), snapshot_pitch_rad(world));

  using Clock = std::chrono::steady_clock;
  std::vector<double> draw_ms;
  std::vector<double> png_ms;
  const std::filesystem::path png =
      args.png_path.empty() ? std::filesystem::temp_directory_path() / ("hapsim_snapshot_bench.png")
                            : std::filesystem::path(args.png_path);
  double t_s = 0.0;
  double cpu_draw_viewer_s = 0.0;
  double cpu_draw_raster_s = 0.0;
  for (int frame = -2; frame < args.frames; ++frame) {  // two warm-up pictures (shader compiles)
    for (int i = 0; i < args.steps_between; ++i) {
      device.write(world.step(device.read(t_s), dt_s).command);
      t_s += dt_s;
    }
    const RenderCpuTime c0 = render_cpu_time_now();
    const auto a = Clock::now();
    drawn.update_from_world(world);
    const std::vector<std::uint8_t>& rgba = writer.render(drawn.scene(), camera);
    const auto b = Clock::now();
    const RenderCpuTime c1 = render_cpu_time_now();
    write_png(png.string(), w, h, rgba);
    const auto c = Clock::now();
    if (frame >= 0) {
      draw_ms.push_back(std::chrono::duration<double, std::milli>(b - a).count());
      png_ms.push_back(std::chrono::duration<double, std::milli>(c - b).count());
      cpu_draw_viewer_s += c1.viewer_thread_s - c0.viewer_thread_s;
      cpu_draw_raster_s += c1.rasteriser_s - c0.rasteriser_s;
    }
  }
  const double n = static_cast<double>(args.frames);
  std::printf("snapshot     %s, %dx%d, %d samples, %s\n", args.scene.c_str(), w, h,
              writer.samples(), writer.renderer_name().c_str());
  std::printf(
      "per picture  update + draw + read back: p50 %.1f ms (CPU: this thread %.1f ms, "
      "rasteriser threads %.1f ms); PNG encode p50 %.1f ms; %d pictures, %d steps apart\n",
      nearest_rank_percentile(draw_ms, 0.5), 1e3 * cpu_draw_viewer_s / n,
      1e3 * cpu_draw_raster_s / n, nearest_rank_percentile(png_ms, 0.5), args.frames,
      args.steps_between);
}

}  // namespace

void add_snapshot_bench(CLI::App& bench) {
  auto args = std::make_shared<SnapshotBenchArgs>();
  CLI::App* snapshot = bench.add_subcommand(
      "snapshot",
      "What one headless picture costs (hapsim run --snapshot): update, offscreen draw and read "
      "back, PNG encode, per picture of the scene's run");
  snapshot->add_option("scene", args->scene, "Scene file (JSON)")->required();
  snapshot->add_option("--data", args->data_dir, "Real-data folder for scenes that use one");
  snapshot->add_option("--frames", args->frames, "Pictures timed (default 30)")
      ->check(CLI::Range(1, 100000));
  snapshot
      ->add_option("--steps-between", args->steps_between,
                   "Haptic steps of the scene's script between pictures (default 50)")
      ->check(CLI::Range(0, 1000000));
  snapshot
      ->add_option("--samples", args->samples,
                   "Multisampling (default 4, as hapsim run --snapshot draws; 1: none)")
      ->check(CLI::Range(1, 16));
  snapshot->add_option("--size", args->size, "WIDTHxHEIGHT (default 1280x720)");
  snapshot->add_option("--png", args->png_path,
                       "Where the last picture goes (default: a temp file)");
  snapshot->callback([args] { run_snapshot_bench(*args); });
}

}  // namespace hapsim::app
