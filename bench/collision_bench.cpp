// Google Benchmark view of the collision cases (bench/collision_cases.h): one benchmark per
// mesh/workload/method, named "collision/<mesh>/<workload>/<method>". Each iteration is one
// query, cycling through the workload's fixed points (the trajectory in order, so hints work).
// Meshes: the quick list by default; HAPSIM_BENCH_FULL=1 for the full list (1M triangles too).
// For the median/p99 table and JSON, use `hapsim bench collision`.
#include "bench/collision_cases.h"

#include <benchmark/benchmark.h>

#include <cstdlib>
#include <iostream>
#include <map>
#include <memory>
#include <string>

namespace {

using namespace hapsim;
using namespace hapsim::bench;

/// Keeps one mesh (with its points) and one built method alive; benchmarks run in registration
/// order (mesh, method, workload), so each structure is built once.
struct Cache {
  std::string mesh_name;
  std::unique_ptr<BenchMesh> mesh;
  std::map<Workload, std::vector<Vec3>> points;
  std::string method_name;
  std::unique_ptr<BenchMethod> method;
};

Cache& cache() {
  static Cache c;
  return c;
}

std::optional<std::filesystem::path> data_dir() { return default_data_dir(); }

constexpr std::size_t kPoints = 20000;
constexpr std::uint64_t kSeed = 20240611;

void run_case(benchmark::State& state, const std::string& mesh_name, Workload workload,
              const std::string& method_name) {
  Cache& c = cache();
  if (c.mesh_name != mesh_name) {
    c.method.reset();
    c.method_name.clear();
    c.mesh = std::make_unique<BenchMesh>(make_bench_mesh(mesh_name, data_dir()));
    c.points.clear();
    c.mesh_name = mesh_name;
  }
  if (!c.points.contains(workload)) {
    c.points[workload] = make_workload_points(c.mesh->mesh, workload, kPoints, kSeed);
  }
  if (c.method_name != method_name) {
    c.method.reset();
    c.method = make_method(method_name, c.mesh->mesh);
    c.method_name = method_name;
  }
  const std::vector<Vec3>& points = c.points[workload];
  c.method->reset();
  std::size_t i = 0;
  for (auto _ : state) {
    benchmark::DoNotOptimize(c.method->query(points[i]));
    if (++i == points.size()) {
      i = 0;
      c.method->reset();
    }
  }
  state.counters["triangles"] = static_cast<double>(c.mesh->mesh.triangle_count());
  state.counters["bytes_per_triangle"] =
      static_cast<double>(c.method->memory_bytes()) /
      static_cast<double>(c.mesh->mesh.triangle_count());
}

}  // namespace

int main(int argc, char** argv) {
  const char* full_env = std::getenv("HAPSIM_BENCH_FULL");
  const bool full = full_env != nullptr && std::string(full_env) == "1";
  for (const std::string& mesh : collision_mesh_names(!full, data_dir())) {
    for (const std::string& method : available_methods()) {
      for (const Workload workload : {Workload::kTrajectory, Workload::kUniform}) {
        benchmark::RegisterBenchmark(
            ("collision/" + mesh + "/" + to_string(workload) + "/" + method).c_str(),
            [=](benchmark::State& state) { run_case(state, mesh, workload, method); })
            ->Unit(benchmark::kNanosecond);
      }
    }
  }
  benchmark::Initialize(&argc, argv);
  if (benchmark::ReportUnrecognizedArguments(argc, argv)) {
    return 1;
  }
  benchmark::RunSpecifiedBenchmarks();
  benchmark::Shutdown();
  return 0;
}
