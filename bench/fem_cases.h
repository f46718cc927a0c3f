// The FEM body benchmark (issue 29 item 4, `hapsim bench fem`): per tet count, a block of
// tissue-like material (make_tet_block, 80 × 60 × 30 mm as scenes/fem_block.json, its bottom
// face fixed), linear and corotational:
//
// - the bare solver (FemBody, backward Euler, dt 10 ms) under a pressing load on one core: step
//   time and rate (median and worst), CG iterations, factorisation time and memory;
// - the haptic step (World::step) with the block in contact and the FEM deferred (advance_fem()
//   between cycles, outside the timed region: what `hapsim run` does), and the FEM side's coupled
//   update (step + surface + contact patch + compliance);
// - the force error of the 1 kHz local contact model against a full solve at the same device
//   position, along a palpation path (down 6 mm into the top, 20 mm sideways pressed, up) at
//   several speeds. Both with quasi-static integration. The full solve is the quasi-static
//   equilibrium of the FEM body with the contact spring k_c in series at the device position,
//   under the coupling's own contact law (world/fem_coupling.cpp, restated here: the contact is
//   the rest surface's closest point to the tool less its patch's displacement, the load spread
//   on the rest-surface vertices within the patch radius, weights 1 − (r/R)², along the patch's
//   rest normal; F = k_c·(tool radius − n·(p − (contact point + patch displacement)))),
//   solved apart from the world by Newton on F with the patch's condensed compliance as slope,
//   each iterate a quasi-static FemBody::step (the coupling's update), iterated until the body has
//   settled. Not solve_static_sphere_contact: a rigid sphere held by
//   node penalties is another contact law, and its difference would not be the local model's.
//
// Shared by `hapsim bench fem` (table and JSON) and, for the block world, the passivity sweep's
// FEM rows (bench/passivity_cases.h).
#pragma once

#include "hapsim/core/progress.h"
#include "hapsim/core/types.h"
#include "hapsim/deform/fem_body.h"
#include "hapsim/world/world_description.h"

#include <atomic>
#include <nlohmann/json.hpp>

#include <array>
#include <cstddef>
#include <memory>
#include <optional>
#include <string>
#include <vector>

namespace hapsim::bench {

/// The bench's block and its contact: scenes/fem_block.json's block and material.
struct FemBlockSpec {
  Vec3 size_m = Vec3(0.04, 0.04, 0.02);
  std::array<int, 3> cells{8, 8, 4};
  FemElasticity elasticity = FemElasticity::kCorotational;
  FemIntegration integration = FemIntegration::kBackwardEuler;
  double dt_s = 0.01;
  FemMaterial material{20e3, 0.45, 1000.0, 2.0, 0.01};
  /// The fingertip's contact with the surface (in series with the tissue's compliance).
  double contact_stiffness_n_per_m = 3000.0;
  double contact_damping_n_s_per_m = 0.5;
  double max_force_n = 10.0;
  double tool_radius_m = 0.005;
  double patch_radius_m = 0.006;
};

/// Cells along each axis for about `target_tets` tetrahedra (6 per cell) in cubic cells.
[[nodiscard]] std::array<int, 3> fem_block_cells(const Vec3& size_m, std::size_t target_tets);

/// A world holding the block (centred on the origin in x and y, its bottom at z = 0, fixed there)
/// as a FEM body, and one spherical tool.
[[nodiscard]] WorldDescription fem_block_world(const FemBlockSpec& spec);

/// The quasi-static equilibrium of the block with the contact spring in series at a tool
/// position: the full solve the local model is compared with (see the file comment). Warm-started
/// from the previous position's equilibrium.
class FemContactReference {
 public:
  explicit FemContactReference(const FemBlockSpec& spec);
  ~FemContactReference();
  FemContactReference(const FemContactReference&) = delete;
  FemContactReference& operator=(const FemContactReference&) = delete;

  /// The force on the tool (world frame = the block's frame) with its centre at `p_m`; nullopt
  /// where the law has no equilibrium the iteration can find (it diverges: the contact point or
  /// normal runs away, the force passes what the tool's overlap with the rest surface allows, or
  /// a static solve fails), and then the body is put back as it was at the last equilibrium.
  [[nodiscard]] std::optional<Vec3> force_at(const Vec3& p_m);

  std::size_t solves = 0;       ///< quasi-static steps (FemBody::step) taken
  int max_iterations = 0;       ///< Newton iterations at the worst converged point
  std::size_t unconverged = 0;  ///< points without an equilibrium

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

/// The palpation path: from 1 mm above the top at x = −10 mm down to `depth_m` beyond the first
/// touch, 20 mm along +x pressed, then up again; held 50 ms at each end.
struct FemPalpationPath {
  Vec3 start_m;
  Vec3 pressed_m;
  Vec3 slid_m;
  Vec3 end_m;
  [[nodiscard]] double length_m() const;
  [[nodiscard]] Vec3 at(double s_m) const;
};
inline constexpr double kFemPalpationDepthM = 0.006;
[[nodiscard]] FemPalpationPath fem_palpation_path(const FemBlockSpec& spec,
                                                  double depth_m = kFemPalpationDepthM);
inline constexpr double kFemPathHoldS = 0.05;

struct FemErrorRow {
  double speed_m_per_s = 0.0;
  std::size_t steps = 0;
  /// Steps left out: the path there lies between reference points without an equilibrium.
  std::size_t undefined_steps = 0;
  /// The largest rendered force over the whole path, N (the undefined stretch included).
  double peak_rendered_n = 0.0;
  /// Steps where the reference or the rendered force is not zero (the RMS is over these).
  std::size_t contact_steps = 0;
  /// The largest reference force along the path, N (the scale of the percentages).
  double peak_force_n = 0.0;
  /// |F_rendered − F_reference| (vectors): what the hand feels, damping included.
  double max_error_n = 0.0;
  double rms_error_n = 0.0;
  /// The same without the damping the stage adds (the model's f0 + K·(x − x0) alone).
  double max_spring_error_n = 0.0;
  double rms_spring_error_n = 0.0;
  /// Path arc length (m) where the largest error was.
  double max_error_at_m = 0.0;
  [[nodiscard]] double max_error_percent() const;
  [[nodiscard]] double rms_error_percent() const;
};

/// The targets: within 5 % of the peak (or 0.05 N) at 10 mm/s, within 10 % at 50 mm/s;
/// none at other speeds (0).
[[nodiscard]] double fem_error_target_fraction(double speed_m_per_s);
[[nodiscard]] bool fem_error_meets_target(const FemErrorRow& row);

struct FemLocalModelError {
  std::vector<FemErrorRow> rows;  ///< one per speed
  std::size_t reference_points = 0;
  std::size_t reference_solves = 0;
  int reference_max_iterations = 0;
  std::size_t reference_unconverged = 0;
  /// Where along the path (m) the reference first had no equilibrium; negative: nowhere.
  double first_unconverged_at_m = -1.0;
  double reference_ms = 0.0;
  /// The full solve's own ripple along the pressed slide, (max − min)/mean of |F| in %: the
  /// force a uniform block gives depends on where the tool is against the mesh's vertices (the
  /// patch's nodes), more as the mesh is coarse beside the patch; the local model lags it.
  double slide_ripple_percent = 0.0;
};

/// The local model against the full solve along the palpation path at each speed (m/s), with
/// `spec`'s elasticity, quasi-static. The reference is solved every `reference_spacing_m` of path
/// and interpolated linearly between.
[[nodiscard]] FemLocalModelError measure_fem_local_model_error(
    FemBlockSpec spec, const std::vector<double>& speeds_m_per_s,
    double depth_m = kFemPalpationDepthM, double reference_spacing_m = 1e-4,
    const ProgressFn& progress = {});

struct FemBenchOptions {
  /// Approximate tet counts; each becomes a block of cubic cells (fem_block_cells).
  std::vector<std::size_t> tet_counts{1000, 5000, 20000};
  std::vector<FemElasticity> elasticities{FemElasticity::kLinear, FemElasticity::kCorotational};
  std::vector<double> speeds_m_per_s{0.010, 0.050, 0.200};
  /// Timed bare FEM steps (backward Euler) per row.
  int fem_steps = 200;
  /// Timed haptic steps per row, s of simulated time in contact.
  double haptic_s = 2.0;
  double reference_spacing_m = 1e-4;
  /// How deep the palpation (and the haptic-step run) presses beyond the first touch.
  double depth_m = kFemPalpationDepthM;
  bool measure_error = true;
  ProgressFn progress;
  /// Set (by SIGINT or SIGTERM) to end the bench after the row under way: the rows done are
  /// returned. Not owned; may be null.
  const std::atomic<bool>* stop = nullptr;
};

struct FemBenchRow {
  std::size_t target_tets = 0;
  std::array<int, 3> cells{};
  std::size_t tets = 0;
  std::size_t nodes = 0;
  std::size_t unknowns = 0;
  FemElasticity elasticity = FemElasticity::kLinear;
  // The bare solver, backward Euler.
  double build_ms = 0.0;  ///< FemBody construction, factorisation included
  double factorisation_ms = 0.0;
  std::size_t factor_memory_bytes = 0;
  std::size_t factor_nonzeros = 0;
  std::size_t fem_steps = 0;
  double step_ms_p50 = 0.0;
  double step_ms_p99 = 0.0;
  double step_ms_max = 0.0;
  double step_ms_mean = 0.0;
  double cg_iterations_mean = 0.0;
  int cg_iterations_max = 0;
  std::size_t unconverged_steps = 0;
  // The world, backward Euler, FEM deferred.
  std::size_t haptic_steps = 0;
  std::size_t haptic_contact_steps = 0;
  double haptic_us_p50 = 0.0;
  double haptic_us_p99 = 0.0;
  double haptic_us_max = 0.0;
  double haptic_us_mean = 0.0;
  double haptic_peak_force_n = 0.0;
  std::size_t fem_updates = 0;
  double update_ms_p50 = 0.0;
  double update_ms_max = 0.0;
  // Quasi-static local model against the full solve.
  bool error_measured = false;
  FemLocalModelError error;

  [[nodiscard]] double rate_hz_median() const {
    return step_ms_p50 > 0.0 ? 1e3 / step_ms_p50 : 0.0;
  }
  [[nodiscard]] double rate_hz_worst() const { return step_ms_max > 0.0 ? 1e3 / step_ms_max : 0.0; }
};

struct FemBenchResult {
  FemBlockSpec block;  ///< the cells of the last row; the rest is every row's
  FemBenchOptions options;
  std::vector<FemBenchRow> rows;
};

[[nodiscard]] FemBenchResult run_fem_bench(const FemBenchOptions& options);
[[nodiscard]] std::string format_fem_table(const FemBenchResult& result);
[[nodiscard]] nlohmann::json fem_bench_to_json(const FemBenchResult& result);

}  // namespace hapsim::bench
