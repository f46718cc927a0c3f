// Google Benchmark view of the haptic step (bench/step_cases.h): one benchmark per case and
// contact method, named "step/<case>/<method>"; each iteration is one World::step on the next
// sample of the scene's palpation script (looping), so deformation and proxy state evolve as in a
// session. The world and its device are the ones `hapsim run --method` builds (make_run_setup,
// scene/run_setup.h), as `hapsim bench step` builds them. For the p50/p99 table and JSON, use
// `hapsim bench step`.
#include "bench/collision_cases.h"
#include "bench/step_cases.h"

#include "hapsim/scene/run_setup.h"
#include "hapsim/scene/scene_file.h"
#include "hapsim/world/world.h"

#include <benchmark/benchmark.h>

#include <iostream>
#include <memory>
#include <string>

namespace {

using namespace hapsim;

void run_case(benchmark::State& state, const bench::StepBenchCase& c, ContactMethod method) {
  SceneLoadOptions load;
  if (c.data_dir) {
    load.data_dir = *c.data_dir;
  }
  RunSetupOptions options;
  options.method = method;
  RunSetup setup = make_run_setup(load_scene(c.scene, load), DeviceChoice::scene_script(), options);
  World& world = *setup.world;
  Device& device = *setup.device;
  const double dt = setup.scene.run.dt_s;
  // The run's length (the script's, unless the scene sets run.duration_s), then again from 0.
  const double end_s = setup.duration_s;
  double t = 0.0;
  // A FEM body's updates run between steps, untimed, as on its own thread in a session.
  const bool fem = world.fem() != nullptr;
  world.set_fem_deferred(fem);
  for (auto _ : state) {
    const DeviceInput input = device.read(t);
    const StepResult& r = world.step(input, dt);
    benchmark::DoNotOptimize(r.command.force_world_n.data());
    if (fem) {
      state.PauseTiming();
      world.advance_fem();
      state.ResumeTiming();
    }
    t += dt;
    if (t > end_s) {
      t = 0.0;
    }
  }
}

}  // namespace

int main(int argc, char** argv) {
  benchmark::Initialize(&argc, argv);
  const auto cases =
      bench::default_step_cases(bench::default_scenes_dir(), bench::default_data_dir());
  if (cases.size() < 3) {
    std::cerr << "hapsim_step_bench: no real-data folder (set HAPSIM_DATA): VHF case skipped\n";
  }
  const std::pair<const char*, ContactMethod> methods[] = {
      {"exact", ContactMethod::kExact},
      {"spheretree", ContactMethod::kSphereTree},
      {"knee", ContactMethod::kKnee}};
  for (const auto& c : cases) {
    for (const auto& [name, method] : methods) {
      benchmark::RegisterBenchmark(("step/" + c.name + "/" + name).c_str(),
                                   [c, m = method](benchmark::State& s) { run_case(s, c, m); })
          ->Unit(benchmark::kMicrosecond);
    }
  }
  benchmark::RunSpecifiedBenchmarks();
  benchmark::Shutdown();
  return 0;
}
