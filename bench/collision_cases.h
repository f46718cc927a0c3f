// The collision benchmark's cases, shared by `hapsim bench collision` (table + JSON) and the
// Google Benchmark binary `hapsim_collision_bench`: the meshes, the two query workloads, every
// method (hapsim's own and the reference libraries) behind one small interface, the per-query
// timing loop, and the row / table / JSON output.
//
// Measurement: for each (mesh, workload) the query points are generated once with a fixed seed.
// Each method is built once per mesh (timed: `build_ms` is the wall time to construct it from a
// TriangleMesh, adapter conversion included), warmed up on the first points of each workload,
// then every query is timed individually with std::chrono::steady_clock; the median cost of an
// empty timing is subtracted. Rows report the per-query median and p99 in nanoseconds.
#pragma once

#include "hapsim/core/progress.h"
#include "hapsim/core/types.h"
#include "hapsim/geometry/triangle_mesh.h"

#include <atomic>
#include <nlohmann/json.hpp>

#include <cstdint>
#include <filesystem>
#include <memory>
#include <optional>
#include <string>
#include <vector>

namespace hapsim::bench {

enum class Workload { kTrajectory, kUniform };

/// "trajectory" or "uniform".
[[nodiscard]] std::string to_string(Workload workload);

/// Contact radius of the `hapsim-contact-radius` rows (metres).
inline constexpr double kContactRadius = 2e-3;

/// One benchmark mesh.
struct BenchMesh {
  std::string name;  // e.g. "bumpy-13.5k", "sheet-256", "knee-tibia"
  TriangleMesh mesh;
};

/// The real-data folder: $HAPSIM_DATA, else the configured HAPSIM_DATA_DIR (../shared/data);
/// nullopt if neither exists (knee meshes are then skipped).
[[nodiscard]] std::optional<std::filesystem::path> default_data_dir();

/// Names of the benchmark meshes, in table order. `quick` leaves out the 1M-triangle sphere and
/// the whole assembled knee. Knee meshes are listed only when the loader and the data exist.
[[nodiscard]] std::vector<std::string> collision_mesh_names(
    bool quick, const std::optional<std::filesystem::path>& data_dir);
/// Every name `make_bench_mesh` accepts (for --help and validation).
[[nodiscard]] std::vector<std::string> all_collision_mesh_names();
/// Builds (or loads) a benchmark mesh by name; throws hapsim::Error on an unknown name or a
/// missing data folder. Meshes are in metres.
[[nodiscard]] BenchMesh make_bench_mesh(const std::string& name,
                                        const std::optional<std::filesystem::path>& data_dir);

/// The exact closest point used to generate trajectories and check every method.
struct ReferenceAnswer {
  Vec3 point = Vec3::Zero();
  std::uint32_t triangle = kNoTriangle;
};

/// Query points for one workload, fixed seed.
/// trajectory: a smooth random walk over the surface (0.05 mm steps, slowly turning heading,
///   bouncing off open boundaries), each point offset along the interpolated vertex normal by a
///   smooth function of arc length within ±5 mm.
/// uniform: uniform in the mesh's bounding box (flat axes, e.g. a sheet's z, padded to ±5 mm).
[[nodiscard]] std::vector<Vec3> make_workload_points(const TriangleMesh& mesh, Workload workload,
                                                     std::size_t count, std::uint64_t seed);

/// One query method behind a uniform interface. `query` returns the unsigned distance to the
/// surface (for the contact-radius method: the distance if within the radius, +inf otherwise).
class BenchMethod {
 public:
  virtual ~BenchMethod() = default;
  [[nodiscard]] virtual const std::string& name() const = 0;
  /// Forgets any hint (start of a workload).
  virtual void reset() = 0;
  virtual double query(const Vec3& p) = 0;
  [[nodiscard]] virtual std::size_t memory_bytes() const = 0;
  /// True for the reference libraries (they define "fastest library").
  [[nodiscard]] virtual bool is_library() const = 0;
};

/// Methods in this build, in table order: hapsim-exact, hapsim-spheretree,
/// hapsim-contact-radius, then cgal, cgal-hint, fcl, embree where built.
[[nodiscard]] std::vector<std::string> available_methods();
/// Every method name the benchmark knows (built or not).
[[nodiscard]] std::vector<std::string> all_method_names();
/// Builds a method over `mesh` (which must outlive it); throws hapsim::Error if not available.
[[nodiscard]] std::unique_ptr<BenchMethod> make_method(const std::string& name,
                                                       const TriangleMesh& mesh);

/// One result row (the JSON schema: the first eight fields are required, the rest are extra).
struct CollisionRow {
  std::string mesh;
  std::size_t triangles = 0;
  std::string workload;
  std::string method;
  double median_ns = 0.0;
  double p99_ns = 0.0;
  double build_ms = 0.0;
  double bytes_per_triangle = 0.0;
  // Extras.
  double mean_ns = 0.0;
  std::size_t query_count = 0;
  /// median_ns / (fastest library's median_ns on the same mesh and workload); 0 if no library.
  double ratio_to_fastest_library = 0.0;
  double p99_ratio_to_fastest_library = 0.0;
  /// Largest |distance - reference distance| over the workload (metres); for contact-radius,
  /// over the points where either says "contact".
  double max_distance_error = 0.0;
  /// Points where the method disagrees with the reference beyond 1e-9 m (or, for contact-radius,
  /// on contact vs no contact).
  std::size_t mismatches = 0;
};

struct CollisionBenchOptions {
  bool quick = false;
  /// Mesh names to run; empty = collision_mesh_names(quick, data_dir).
  std::vector<std::string> meshes;
  /// Method names to run; empty = available_methods().
  std::vector<std::string> methods;
  /// Workloads to run (both by default).
  std::vector<Workload> workloads{Workload::kTrajectory, Workload::kUniform};
  /// Timed queries per (mesh, workload, method); 0 = 20000 (quick: 4000).
  std::size_t queries = 0;
  /// Untimed warm-up queries before each timed pass; 0 = min(1000, queries / 4).
  std::size_t warmup = 0;
  std::uint64_t seed = 20240611;
  std::optional<std::filesystem::path> data_dir;
  /// Called with a label ("bumpy-100k: build fcl") and a fraction of the whole run.
  ProgressFn progress;
  /// Set (by SIGINT or SIGTERM) to end the bench after the row under way: the rows done are
  /// returned. Not owned; may be null.
  const std::atomic<bool>* stop = nullptr;
};

/// Runs every (mesh, workload, method) and returns the rows, ratios filled in.
[[nodiscard]] std::vector<CollisionRow> run_collision_bench(const CollisionBenchOptions& options);

/// Fills ratio_to_fastest_library for rows grouped by (mesh, workload).
void compute_ratios(std::vector<CollisionRow>& rows);

/// The human table (one block per mesh and workload) with a header saying what was measured.
[[nodiscard]] std::string format_table(const std::vector<CollisionRow>& rows);

[[nodiscard]] nlohmann::json rows_to_json(const std::vector<CollisionRow>& rows);

}  // namespace hapsim::bench
