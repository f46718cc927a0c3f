// Google Benchmark view of the FEM body (deform/fem_body.h, SPEC §12): a 60 × 60 × 30 mm slab of
// soft tissue (make_tet_block, bottom face fixed, E 20 kPa, ν 0.45) pressed on the top by a
// Gaussian patch of nodal forces that swings between 0.4 and 2 N at 2 Hz, so the body keeps moving
// and a warm-started solver never meets an already-solved system. Per tet count (≈1k, 5k, 20k) and
// elasticity (linear, corotational):
//   fem/step/<elasticity>/<tets>        one backward Euler step, dt 10 ms
//   fem/quasistatic/<elasticity>/<tets> one quasi-static step (corotational: 4 rotation updates)
//   fem/static/<elasticity>/<tets>      solve_static() to convergence, the load changed each time
// and, apart because factoring 80k tets takes seconds, fem_large/step/<elasticity>/<tets>; skip
// those with --benchmark_filter='^fem/'.
// Counters: Hz (steps per CPU second), tets, nodes, unknowns, factor_ms and factor_MB (the body's
// own figures for its factorisation), setup_ms (the whole construction), cg_iter (per step; 0 for
// a direct solve) and unconverged (steps whose solver stopped short of its tolerance).
// The body is built once per benchmark, not once per Google Benchmark run, and reset() between
// runs: the factorisation is what we measure with the counters, not what we repeat.
#include "hapsim/deform/fem_body.h"
#include "hapsim/geometry/tet_mesh.h"

#include <benchmark/benchmark.h>

#include <array>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <memory>
#include <numbers>
#include <string>
#include <utility>
#include <vector>

namespace {

using namespace hapsim;

enum class Mode { kStep, kQuasiStaticStep, kSolveStatic };

const Vec3 kSlabSize_m(0.060, 0.060, 0.030);
constexpr double kPressPeak_n = 2.0;
constexpr double kPressFrequency_hz = 2.0;
constexpr double kPatchSigma_m = 0.008;

// The slab, its fixed bottom and the press, built once per benchmark.
struct Prepared {
  std::string key;
  std::unique_ptr<FemBody> body;
  std::vector<std::uint32_t> top_nodes;
  std::vector<double> top_weights;  ///< sum to 1
  std::vector<FemNodeForce> loads;  ///< reused every step
  double setup_ms = 0.0;
};

Prepared& prepare(const std::array<int, 3>& cells, FemElasticity elasticity, Mode mode) {
  // One body at a time: an 80k-tet factorisation is hundreds of MB.
  static Prepared cached;
  const std::string key = std::to_string(cells[0]) + "x" + std::to_string(cells[1]) + "x" +
                          std::to_string(cells[2]) + "/" + std::string(to_string(elasticity)) +
                          "/" + std::to_string(static_cast<int>(mode));
  if (cached.key == key && cached.body) {
    cached.body->reset();
    return cached;
  }
  cached = Prepared{};
  TetMesh mesh = make_tet_block(kSlabSize_m, cells);
  std::vector<std::uint32_t> fixed;
  for (std::size_t i = 0; i < mesh.node_count(); ++i) {
    const Vec3& p = mesh.nodes[i];
    if (p.z() < 1e-9) {
      fixed.push_back(static_cast<std::uint32_t>(i));
    } else if (p.z() > kSlabSize_m.z() - 1e-9) {
      cached.top_nodes.push_back(static_cast<std::uint32_t>(i));
    }
  }
  const Vec3 centre_m(0.5 * kSlabSize_m.x(), 0.5 * kSlabSize_m.y(), kSlabSize_m.z());
  double weight_sum = 0.0;
  for (const std::uint32_t n : cached.top_nodes) {
    const double r2 = (mesh.nodes[n] - centre_m).squaredNorm();
    cached.top_weights.push_back(std::exp(-r2 / (2.0 * kPatchSigma_m * kPatchSigma_m)));
    weight_sum += cached.top_weights.back();
  }
  for (double& w : cached.top_weights) {
    w /= weight_sum;
  }
  cached.loads.resize(cached.top_nodes.size());

  FemMaterial tissue;
  tissue.youngs_modulus_pa = 20e3;
  tissue.poisson_ratio = 0.45;
  tissue.density_kg_per_m3 = 1000.0;
  tissue.rayleigh_mass_per_s = 1.0;
  tissue.rayleigh_stiffness_s = 0.002;
  FemOptions options;
  options.elasticity = elasticity;
  options.integration =
      mode == Mode::kStep ? FemIntegration::kBackwardEuler : FemIntegration::kQuasiStatic;
  options.dt_s = 0.01;
  const auto start = std::chrono::steady_clock::now();
  cached.body =
      std::make_unique<FemBody>(std::move(mesh), std::vector<FemRegionMaterial>{{0, tissue}},
                                std::move(fixed), options, "fem bench slab");
  cached.setup_ms =
      std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
  cached.key = key;
  return cached;
}

void set_press(Prepared& p, double t_s) {
  const double magnitude_n =
      kPressPeak_n * (0.6 + 0.4 * std::sin(2.0 * std::numbers::pi * kPressFrequency_hz * t_s));
  for (std::size_t k = 0; k < p.top_nodes.size(); ++k) {
    p.loads[k] = {p.top_nodes[k], Vec3(0.0, 0.0, -magnitude_n * p.top_weights[k])};
  }
  p.body->set_loads(p.loads);
}

void run_fem(benchmark::State& state, std::array<int, 3> cells, FemElasticity elasticity,
             Mode mode) {
  Prepared& p = prepare(cells, elasticity, mode);
  FemBody& body = *p.body;
  const double dt_s = body.options().dt_s;
  double t_s = 0.0;
  double cg_iterations = 0.0;
  double unconverged = 0.0;
  for (auto _ : state) {
    set_press(p, t_s);
    const FemStepStats stats = mode == Mode::kSolveStatic ? body.solve_static() : body.step();
    cg_iterations += stats.cg_iterations;
    unconverged += stats.converged ? 0.0 : 1.0;
    benchmark::DoNotOptimize(body.positions().data());
    t_s += dt_s;
  }
  using benchmark::Counter;
  state.counters["Hz"] = Counter(static_cast<double>(state.iterations()), Counter::kIsRate);
  state.counters["tets"] = static_cast<double>(body.tet_count());
  state.counters["nodes"] = static_cast<double>(body.node_count());
  state.counters["unknowns"] = static_cast<double>(body.unknowns());
  state.counters["factor_ms"] = body.factorisation_ms();
  state.counters["factor_MB"] = static_cast<double>(body.factor_memory_bytes()) / 1e6;
  state.counters["setup_ms"] = p.setup_ms;
  state.counters["cg_iter"] = Counter(cg_iterations, Counter::kAvgIterations);
  state.counters["unconverged"] = unconverged;
}

}  // namespace

int main(int argc, char** argv) {
  benchmark::Initialize(&argc, argv);
  // make_tet_block makes 6 tets per cell.
  const std::array<std::array<int, 3>, 3> sizes{{{8, 8, 3}, {12, 12, 6}, {18, 18, 10}}};
  const std::array<int, 3> large{30, 30, 15};
  const std::pair<const char*, FemElasticity> elasticities[] = {
      {"linear", FemElasticity::kLinear}, {"corotational", FemElasticity::kCorotational}};
  const std::pair<const char*, Mode> modes[] = {{"step", Mode::kStep},
                                                {"quasistatic", Mode::kQuasiStaticStep},
                                                {"static", Mode::kSolveStatic}};
  const auto tets = [](const std::array<int, 3>& c) {
    return std::to_string(6 * c[0] * c[1] * c[2]);
  };
  for (const auto& [mode_name, mode] : modes) {
    for (const auto& [elasticity_name, elasticity] : elasticities) {
      for (const auto& cells : sizes) {
        benchmark::RegisterBenchmark(
            (std::string("fem/") + mode_name + "/" + elasticity_name + "/" + tets(cells)).c_str(),
            [cells, e = elasticity, m = mode](benchmark::State& s) { run_fem(s, cells, e, m); })
            ->Unit(benchmark::kMillisecond);
      }
    }
  }
  for (const auto& [elasticity_name, elasticity] : elasticities) {
    benchmark::RegisterBenchmark(
        (std::string("fem_large/step/") + elasticity_name + "/" + tets(large)).c_str(),
        [large, e = elasticity](benchmark::State& s) { run_fem(s, large, e, Mode::kStep); })
        ->Unit(benchmark::kMillisecond);
  }
  benchmark::RunSpecifiedBenchmarks();
  benchmark::Shutdown();
  return 0;
}
