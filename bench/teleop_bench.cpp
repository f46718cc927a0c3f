// The teleoperation step (issue 4 target: p99 under 50 µs) and its inverse kinematics: a full
// cycle of the scripted pick-and-place (master FK, slave IK at its speed limits, gripper–ball–
// sheet contacts, sheet update, ball dynamics), IK while tracking (last cycle's answer as seed)
// and IK from cold, for the procedural Motoman and the GP7 when its URDF is there. The per-step
// percentiles of the whole scene come from `hapsim run scenes/teleop.json --json FILE`.
#include "hapsim/kinematics/procedural_motoman.h"
#include "hapsim/kinematics/urdf_chain.h"
#include "hapsim/scene/run_setup.h"
#include "hapsim/scene/scene_file.h"
#include "hapsim/world/world.h"

#include <benchmark/benchmark.h>

#include <filesystem>
#include <memory>
#include <random>

namespace hapsim {
namespace {

std::shared_ptr<const SerialChain> slave(bool gp7) {
  if (!gp7) {
    return std::make_shared<const SerialChain>(make_procedural_motoman());
  }
  UrdfChainOptions o;
  o.load_collision_meshes = true;  // its links' bodies, as hapsim run builds them
  return std::make_shared<const SerialChain>(load_urdf_chain(
      std::filesystem::path(HAPSIM_BENCH_DEFAULT_DATA_DIR) / "motoman_gp7" / "gp7.urdf", o));
}

bool have_gp7() {
  return std::filesystem::exists(std::filesystem::path(HAPSIM_BENCH_DEFAULT_DATA_DIR) /
                                 "motoman_gp7" / "gp7.urdf");
}

// Every cycle of the scripted pick-and-place, round and round (the world restarts each lap): the
// world and the master's script are the ones `hapsim run scenes/teleop.json` (teleop_gp7.json for
// the GP7) builds, through make_run_setup.
void BM_TeleopStep(benchmark::State& state) {
  const bool gp7 = state.range(0) != 0;
  if (gp7 && !have_gp7()) {
    state.SkipWithError("GP7 URDF not found");
    return;
  }
  const std::filesystem::path scenes(HAPSIM_BENCH_SCENES_DIR);
  SceneLoadOptions load;
  if (gp7) {
    load.data_dir = std::filesystem::path(HAPSIM_BENCH_DEFAULT_DATA_DIR) / "motoman_gp7";
  }
  const SceneDescription scene =
      load_scene(scenes / (gp7 ? "teleop_gp7.json" : "teleop.json"), load);
  RunSetup setup = make_run_setup(scene, DeviceChoice::scene_script());
  const double dt_s = setup.scene.run.dt_s;
  const auto steps = static_cast<int>(setup.duration_s / dt_s);
  std::vector<DeviceInput> inputs;
  for (int k = 1; k <= steps; ++k) {
    inputs.push_back(setup.device->read(k * dt_s));
  }
  std::size_t k = 0;
  for (auto _ : state) {
    benchmark::DoNotOptimize(setup.world->step(inputs[k], dt_s));
    if (++k == inputs.size()) {
      state.PauseTiming();
      setup.world = make_run_setup(scene, DeviceChoice::scene_script()).world;
      k = 0;
      state.ResumeTiming();
    }
  }
}
BENCHMARK(BM_TeleopStep)->Arg(0)->Arg(1)->ArgName("gp7")->Unit(benchmark::kMicrosecond);

// IK tracking a path (seed = last answer, 1 ms of motion apart) and from cold (zero seed).
void BM_Ik(benchmark::State& state) {
  const bool gp7 = state.range(0) != 0;
  const bool cold = state.range(1) != 0;
  if (gp7 && !have_gp7()) {
    state.SkipWithError("GP7 URDF not found");
    return;
  }
  const std::shared_ptr<const SerialChain> arm = slave(gp7);
  std::mt19937 rng(1);
  std::vector<std::vector<double>> path;
  std::vector<double> q(static_cast<std::size_t>(arm->dof()));
  for (std::size_t i = 0; i < q.size(); ++i) {
    const ChainJoint& j = arm->joints()[i];
    q[i] = 0.5 * (std::max(j.lower, -3.0) + std::min(j.upper, 3.0)) + 0.2;
  }
  for (int k = 0; k < 1000; ++k) {
    for (std::size_t i = 0; i < q.size(); ++i) {
      q[i] += 0.002 * std::sin(0.01 * k + static_cast<double>(i));  // ~2 rad/s per joint
    }
    path.push_back(q);
  }
  std::vector<Iso3> targets;
  for (const auto& p : path) {
    targets.push_back(arm->forward(p));
  }
  IkOptions o = cold ? IkOptions{} : SlaveFollowerOptions::real_time_ik();
  std::vector<double> answer = path[0], zero(q.size(), 0.0);
  std::size_t k = 0, reached = 0, total = 0;
  for (auto _ : state) {
    const IkResult r = solve_ik(*arm, targets[k], cold ? zero : answer, answer, o);
    reached += r.reached ? 1 : 0;
    ++total;
    k = (k + 1) % targets.size();
  }
  state.counters["reached_%"] = 100.0 * static_cast<double>(reached) / static_cast<double>(total);
}
BENCHMARK(BM_Ik)
    ->ArgsProduct({{0, 1}, {0, 1}})
    ->ArgNames({"gp7", "cold"})
    ->Unit(benchmark::kMicrosecond);

}  // namespace
}  // namespace hapsim

BENCHMARK_MAIN();
