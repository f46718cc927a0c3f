// What the real-time pieces cost (issue 5): the knee's haptic step with and without publishing
// (the viewer's triple-buffered snapshot with deformed vertices copied by delta, and the ring of
// cycle records), side by side in the same run; the triple buffer's own hand-over; and drawing
// one 1280x720 frame of the knee offscreen on Mesa's software rasteriser (what bounds the
// viewer's fps). The knee's world and device are the ones `hapsim run` builds for the scene
// (make_run_setup, scene/run_setup.h: materials no stiffer than the device's rating). The loop's
// timing over a minute comes from scripts/measure-realtime.sh.
#include "hapsim/core/triple_buffer.h"
#include "hapsim/render/snapshot_writer.h"
#include "hapsim/render/world_scene.h"
#include "hapsim/runtime/world_haptic_client.h"
#include "hapsim/scene/run_setup.h"
#include "hapsim/scene/scene_file.h"

#include <benchmark/benchmark.h>

#include <array>
#include <cmath>

#include <filesystem>
#include <memory>

namespace hapsim {
namespace {

struct Knee {
  RunSetup setup = make_run_setup(
      load_scene(std::filesystem::path(HAPSIM_BENCH_SCENES_DIR) / "knee_procedural.json"),
      DeviceChoice::scene_script());
  World& world = *setup.world;
  Device& device = *setup.device;
};

Knee& knee() {
  static Knee k;
  return k;
}

// The palpation script, cycle after cycle (lap after lap), through the client or the world alone.
void BM_KneeStep(benchmark::State& state) {
  const bool publish = state.range(0) != 0;
  Knee& k = knee();
  k.world.reset();
  WorldHapticClientOptions o;
  o.publish_snapshots = publish;
  o.record_capacity = publish ? 4096 : 0;
  WorldHapticClient client(k.world, o);
  // The run's length (the palpation script's: the scene sets no run.duration_s), lap after lap.
  const double end_s = k.setup.duration_s;
  const double dt = k.setup.scene.run.dt_s;
  std::uint64_t i = 0;
  for (auto _ : state) {
    const double t = std::fmod(static_cast<double>(i) * dt, end_s);
    const DeviceInput in = k.device.read(t);
    const DeviceCommand& command = client.step(in, dt);
    if (publish) {
      HapticCycle cycle;
      cycle.index = i;
      cycle.time_s = t;
      cycle.input = &in;
      cycle.fresh = &command;
      cycle.output = &command;
      client.after_cycle(cycle);
      // The consumer keeps up (as the run's bookkeeping does).
      while (client.records()->front() != nullptr) {
        client.records()->pop();
      }
      client.snapshots()->update();
    }
    benchmark::DoNotOptimize(command);
    ++i;
  }
  state.SetLabel(publish ? "step + publish (snapshot, record)" : "step alone");
}
BENCHMARK(BM_KneeStep)->Arg(0)->Arg(1)->Unit(benchmark::kMicrosecond);

void BM_TripleBufferHandOver(benchmark::State& state) {
  TripleBuffer<std::array<double, 64>> buffer(std::array<double, 64>{});
  double v = 0.0;
  for (auto _ : state) {
    buffer.write_slot()[0] = v;
    buffer.publish();
    buffer.update();
    v = buffer.read_slot()[0] + 1.0;
  }
  benchmark::DoNotOptimize(v);
}
BENCHMARK(BM_TripleBufferHandOver);

// One viewer-sized frame of the knee (rest shape plus the dent of the current step), offscreen.
void BM_KneeFrame1280x720(benchmark::State& state) {
  Knee& k = knee();
  std::unique_ptr<SnapshotWriter> writer;
  try {
    writer = std::make_unique<SnapshotWriter>(1280, 720, static_cast<int>(state.range(0)));
  } catch (const std::exception& e) {
    state.SkipWithError(e.what());
    return;
  }
  WorldScene view(k.world);
  const OrbitCamera camera = framed_camera(view.rest_bounds_world(), 1280.0 / 720.0, 1.95, 0.3);
  view.update_from_world(k.world);
  for (auto _ : state) {
    benchmark::DoNotOptimize(writer->render(view.scene(), camera).data());
  }
  state.SetLabel(std::to_string(state.range(0)) + " sample(s) per pixel, draw + read back");
}
BENCHMARK(BM_KneeFrame1280x720)->Arg(1)->Arg(4)->Unit(benchmark::kMillisecond)->MinTime(1.0);

}  // namespace
}  // namespace hapsim

BENCHMARK_MAIN();
