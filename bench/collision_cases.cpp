#include "bench/collision_cases.h"

#include "hapsim/core/data_dir.h"
#include "hapsim/core/error.h"
#include "hapsim/core/statistics.h"
#include "hapsim/core/stopwatch.h"
#include "hapsim/geometry/procedural.h"
#include "oracles/closest_point_oracle.h"

#ifdef HAPSIM_BENCH_HAVE_MESH_BVH
#include "hapsim/collision/mesh_bvh.h"
#endif
#ifdef HAPSIM_BENCH_HAVE_SPHERE_TREE
#include "hapsim/collision/sphere_tree.h"
#endif
#ifdef HAPSIM_BENCH_HAVE_MESH_IO
#include "hapsim/geometry/mesh_io.h"
#endif
#include "hapsim/collision/point_triangle.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <functional>
#include <map>
#include <numbers>
#include <random>
#include <sstream>

namespace hapsim::bench {
namespace {

constexpr double kStep = 0.05e-3;          // trajectory step (metres)
constexpr double kOffsetAmplitude = 5e-3;  // trajectory offset along the normal, ±
constexpr double kAgreeTolerance = 1e-9;   // metres: "same distance" for the cross-check

constexpr const char* kKneeFolder = "knee_vhf_left/stl";
constexpr const char* kKneeTibia = "VHF_Left_Bone_Tibia_smooth.stl";

bool knee_available(const std::optional<std::filesystem::path>& data_dir) {
#ifdef HAPSIM_BENCH_HAVE_MESH_IO
  std::error_code ec;
  return data_dir && std::filesystem::is_regular_file(*data_dir / kKneeFolder / kKneeTibia, ec);
#else
  (void)data_dir;
  return false;
#endif
}

// ---- the exact reference (trajectory generation and the cross-check) -----------------------

/// Closest point by the project's exact BVH when built, else by the first reference library
/// (only while the hapsim query sources are not in the tree).
class Reference {
 public:
  explicit Reference(const TriangleMesh& mesh) : mesh_(mesh) {
#ifdef HAPSIM_BENCH_HAVE_MESH_BVH
    bvh_ = std::make_unique<MeshBvh>(mesh);
#else
    const auto names = oracle::available_oracles();
    if (names.empty()) {
      throw Error("hapsim bench", "no exact closest-point method is built");
    }
    oracle_ = oracle::make_oracle(names.back(), mesh);
#endif
  }

  [[nodiscard]] ReferenceAnswer closest(const Vec3& p) {
#ifdef HAPSIM_BENCH_HAVE_MESH_BVH
    const SurfacePoint s = bvh_->closest_point(p, &hint_);
    return {s.point, s.triangle};
#else
    const oracle::OracleAnswer a = oracle_->closest(p);
    return {a.point, a.triangle};
#endif
  }

  [[nodiscard]] const TriangleMesh& mesh() const {
    return mesh_;
  }

 private:
  const TriangleMesh& mesh_;
#ifdef HAPSIM_BENCH_HAVE_MESH_BVH
  std::unique_ptr<MeshBvh> bvh_;
  QueryHint hint_;
#else
  std::unique_ptr<oracle::ClosestPointOracle> oracle_;
#endif
};

// ---- workloads ------------------------------------------------------------------------------

std::uint64_t workload_seed(std::uint64_t seed, Workload workload) {
  return seed * 0x9E3779B97F4A7C15ULL + (workload == Workload::kTrajectory ? 1 : 2);
}

Vec3 any_perpendicular(const Vec3& n) {
  const Vec3 axis = std::abs(n.x()) < 0.9 ? Vec3::UnitX() : Vec3::UnitY();
  return n.cross(axis).normalized();
}

/// Interpolated vertex normal at point q on triangle t (barycentric weights).
Vec3 smooth_normal(const TriangleMesh& mesh, const std::vector<Vec3>& normals, std::uint32_t t,
                   const Vec3& q) {
  const auto [a, b, c] = mesh.corners(t);
  const Vec3 n = (b - a).cross(c - a);
  const double area2 = n.squaredNorm();
  const Vec3 face = area2 > 0.0 ? Vec3(n / std::sqrt(area2)) : Vec3::UnitZ();
  if (area2 <= 0.0 || normals.empty()) {
    return face;
  }
  const double wa = std::max(0.0, (c - b).cross(q - b).dot(n) / area2);
  const double wb = std::max(0.0, (a - c).cross(q - c).dot(n) / area2);
  const double wc = std::max(0.0, 1.0 - wa - wb);
  const TriangleIndices& tri = mesh.triangles[t];
  const Vec3 s = wa * normals[tri[0]] + wb * normals[tri[1]] + wc * normals[tri[2]];
  const double len = s.norm();
  return len > 1e-12 ? Vec3(s / len) : face;
}

std::vector<Vec3> trajectory_points(Reference& reference, std::size_t count, std::uint64_t seed) {
  const TriangleMesh& mesh = reference.mesh();
  std::vector<Vec3> normals = mesh.vertex_normals;
  if (normals.size() != mesh.vertices.size()) {
    TriangleMesh copy = mesh;
    copy.compute_vertex_normals();
    normals = std::move(copy.vertex_normals);
  }
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  std::normal_distribution<double> turn(0.0, 0.01);  // heading change per step (radians)

  // Start: a random point on the surface, area-weighted.
  std::vector<double> cumulative(mesh.triangle_count());
  double total = 0.0;
  for (std::size_t t = 0; t < mesh.triangle_count(); ++t) {
    total += 0.5 * mesh.face_normal_area2(t).norm();
    cumulative[t] = total;
  }
  const auto start_t = static_cast<std::uint32_t>(
      std::lower_bound(cumulative.begin(), cumulative.end(), unit(rng) * total) -
      cumulative.begin());
  const auto [a, b, c] = mesh.corners(std::min<std::size_t>(start_t, mesh.triangle_count() - 1));
  double r1 = unit(rng);
  double r2 = unit(rng);
  if (r1 + r2 > 1.0) {
    r1 = 1.0 - r1;
    r2 = 1.0 - r2;
  }
  ReferenceAnswer at = reference.closest(a + r1 * (b - a) + r2 * (c - a));
  Vec3 normal = smooth_normal(mesh, normals, at.triangle, at.point);
  Vec3 heading = any_perpendicular(normal);

  // Offset along the normal: a smooth function of arc length, |h| <= 5 mm.
  const double two_pi = 2.0 * std::numbers::pi;
  const double phase1 = two_pi * unit(rng);
  const double phase2 = two_pi * unit(rng);
  const double k1 = two_pi / 40e-3;
  const double k2 = two_pi / 13e-3;
  const auto offset = [&](double s) {
    return kOffsetAmplitude * (0.6 * std::sin(k1 * s + phase1) + 0.4 * std::sin(k2 * s + phase2));
  };
  const auto offset_slope = [&](double s) {
    return kOffsetAmplitude *
           (0.6 * k1 * std::cos(k1 * s + phase1) + 0.4 * k2 * std::cos(k2 * s + phase2));
  };

  std::vector<Vec3> points;
  points.reserve(count);
  double arc = 0.0;
  for (std::size_t i = 0; i < count; ++i) {
    points.push_back(at.point + offset(arc) * normal);
    // Surface step chosen so the query point itself moves about 0.05 mm.
    const double slope = offset_slope(arc);
    const double ds = kStep / std::sqrt(1.0 + slope * slope);
    const double angle = turn(rng);
    heading = (std::cos(angle) * heading + std::sin(angle) * normal.cross(heading)).normalized();
    ReferenceAnswer next = reference.closest(at.point + ds * heading);
    if ((next.point - at.point).norm() < 0.25 * ds) {
      // Stuck on an open boundary (a sheet's rim): bounce back.
      heading = -heading;
      next = reference.closest(at.point + ds * heading);
    }
    arc += ds;
    at = next;
    normal = smooth_normal(mesh, normals, at.triangle, at.point);
    heading -= heading.dot(normal) * normal;
    heading = heading.norm() > 1e-9 ? Vec3(heading.normalized()) : any_perpendicular(normal);
  }
  return points;
}

std::vector<Vec3> uniform_points(const TriangleMesh& mesh, std::size_t count, std::uint64_t seed) {
  Box3 box = mesh.bounds();
  for (int k = 0; k < 3; ++k) {
    const double half = 0.5 * (box.max()[k] - box.min()[k]);
    if (half < kOffsetAmplitude) {
      const double pad = kOffsetAmplitude - half;
      box.min()[k] -= pad;
      box.max()[k] += pad;
    }
  }
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  std::vector<Vec3> points;
  points.reserve(count);
  for (std::size_t i = 0; i < count; ++i) {
    const Vec3 u(unit(rng), unit(rng), unit(rng));
    points.push_back(box.min() + u.cwiseProduct(box.max() - box.min()));
  }
  return points;
}

std::vector<Vec3> workload_points(Reference& reference, Workload workload, std::size_t count,
                                  std::uint64_t seed) {
  return workload == Workload::kTrajectory
             ? trajectory_points(reference, count, workload_seed(seed, workload))
             : uniform_points(reference.mesh(), count, workload_seed(seed, workload));
}

// ---- methods --------------------------------------------------------------------------------

#if defined(HAPSIM_BENCH_HAVE_MESH_BVH) || defined(HAPSIM_BENCH_HAVE_SPHERE_TREE)
/// hapsim-exact / hapsim-spheretree: closest_point with the previous answer as hint.
/// hapsim-contact-radius: MeshBvh::contact_within(p, 2 mm), hint likewise.
class HapsimMethod final : public BenchMethod {
 public:
  HapsimMethod(std::string name, std::unique_ptr<ProximityQuery> query, bool contact_radius)
      : name_(std::move(name)), query_(std::move(query)), contact_radius_(contact_radius) {}
  [[nodiscard]] const std::string& name() const override { return name_; }
  void reset() override { hint_ = QueryHint{}; }
  double query(const Vec3& p) override {
    if (contact_radius_) {
      SurfacePoint out;
      return query_->contact_within(p, kContactRadius, &out, &hint_) ? std::abs(out.signed_distance)
                                                                     : kInf;
    }
    return std::abs(query_->closest_point(p, &hint_).signed_distance);
  }
  [[nodiscard]] std::size_t memory_bytes() const override { return query_->memory_bytes(); }
  [[nodiscard]] bool is_library() const override { return false; }

 private:
  std::string name_;
  std::unique_ptr<ProximityQuery> query_;
  bool contact_radius_;
  QueryHint hint_;
};
#endif

/// A reference library (the oracle keeps its own hint state where it has one: cgal-hint).
class OracleMethod final : public BenchMethod {
 public:
  explicit OracleMethod(std::unique_ptr<oracle::ClosestPointOracle> oracle)
      : name_(oracle->name()), oracle_(std::move(oracle)) {}
  [[nodiscard]] const std::string& name() const override { return name_; }
  void reset() override {}
  double query(const Vec3& p) override { return oracle_->closest(p).distance; }
  [[nodiscard]] std::size_t memory_bytes() const override { return oracle_->memory_bytes(); }
  [[nodiscard]] bool is_library() const override { return true; }

 private:
  std::string name_;
  std::unique_ptr<oracle::ClosestPointOracle> oracle_;
};

// ---- timing ---------------------------------------------------------------------------------

using Clock = std::chrono::steady_clock;

double timer_overhead_ns() {
  static const double overhead = [] {
    std::vector<double> samples(20000);
    for (double& s : samples) {
      const auto t0 = Clock::now();
      const auto t1 = Clock::now();
      s = static_cast<double>(
          std::chrono::duration_cast<std::chrono::nanoseconds>(t1 - t0).count());
    }
    std::nth_element(samples.begin(), samples.begin() + samples.size() / 2, samples.end());
    return samples[samples.size() / 2];
  }();
  return overhead;
}

struct Timing {
  double median_ns = 0.0;
  double p99_ns = 0.0;
  double mean_ns = 0.0;
  std::vector<double> distances;
};

Timing time_queries(BenchMethod& method, const std::vector<Vec3>& points, std::size_t warmup) {
  volatile double sink = 0.0;
  method.reset();
  for (std::size_t i = 0; i < std::min(warmup, points.size()); ++i) {
    sink = sink + method.query(points[i]);
  }
  method.reset();
  const double overhead = timer_overhead_ns();
  std::vector<double> samples(points.size(), 0.0);
  std::vector<double> distances(points.size(), 0.0);
  Timing timing;
  double sum = 0.0;
  for (std::size_t i = 0; i < points.size(); ++i) {
    const auto t0 = Clock::now();
    const double d = method.query(points[i]);
    const auto t1 = Clock::now();
    distances[i] = d;
    const double ns =
        static_cast<double>(std::chrono::duration_cast<std::chrono::nanoseconds>(t1 - t0).count());
    samples[i] = std::max(0.0, ns - overhead);
    sum += samples[i];
  }
  timing.mean_ns = points.empty() ? 0.0 : sum / static_cast<double>(points.size());
  timing.median_ns = nearest_rank_percentile(samples, 0.5);
  timing.p99_ns = nearest_rank_percentile(samples, 0.99);
  timing.distances = std::move(distances);
  return timing;
}

void check_against_reference(const std::string& method, const std::vector<double>& distances,
                             const std::vector<double>& reference, CollisionRow& row) {
  const bool contact = method == "hapsim-contact-radius";
  for (std::size_t i = 0; i < distances.size(); ++i) {
    const double d = distances[i];
    const double ref = reference[i];
    if (contact) {
      if (std::isinf(d)) {
        if (ref < kContactRadius - kAgreeTolerance) {
          ++row.mismatches;  // missed a contact
        }
        continue;
      }
      if (ref > kContactRadius + kAgreeTolerance) {
        ++row.mismatches;  // reported a contact that is not there
      }
    }
    const double error = std::abs(d - ref);
    row.max_distance_error = std::max(row.max_distance_error, std::isfinite(error) ? error : kInf);
    if (!(error <= kAgreeTolerance)) {
      ++row.mismatches;
    }
  }
}

std::string format_count(std::size_t n) {
  char buffer[32];
  if (n >= 1000000) {
    std::snprintf(buffer, sizeof buffer, "%.2fM", static_cast<double>(n) / 1e6);
  } else if (n >= 1000) {
    std::snprintf(buffer, sizeof buffer, "%.1fk", static_cast<double>(n) / 1e3);
  } else {
    std::snprintf(buffer, sizeof buffer, "%zu", n);
  }
  return buffer;
}

}  // namespace

// ---- public API -----------------------------------------------------------------------------

std::string to_string(Workload workload) {
  return workload == Workload::kTrajectory ? "trajectory" : "uniform";
}

std::optional<std::filesystem::path> default_data_dir() {
  return find_data_dir(HAPSIM_BENCH_DEFAULT_DATA_DIR);
}

std::vector<std::string> all_collision_mesh_names() {
  return {"bumpy-13.5k", "bumpy-100k", "bumpy-1m", "knee-tibia",
          "knee-all",    "sheet-16",   "sheet-256"};
}

std::vector<std::string> collision_mesh_names(
    bool quick, const std::optional<std::filesystem::path>& data_dir) {
  std::vector<std::string> names{"bumpy-13.5k", "bumpy-100k"};
  if (!quick) {
    names.emplace_back("bumpy-1m");
  }
  if (knee_available(data_dir)) {
    names.emplace_back("knee-tibia");
    if (!quick) {
      names.emplace_back("knee-all");
    }
  }
  names.emplace_back("sheet-16");
  names.emplace_back("sheet-256");
  return names;
}

BenchMesh make_bench_mesh(const std::string& name,
                          const std::optional<std::filesystem::path>& data_dir) {
  BenchMesh out{name, {}};
  if (name == "bumpy-13.5k") {
    out.mesh = make_bumpy_sphere(13500);
  } else if (name == "bumpy-100k") {
    out.mesh = make_bumpy_sphere(100000);
  } else if (name == "bumpy-1m") {
    out.mesh = make_bumpy_sphere(1000000);
  } else if (name == "sheet-16") {
    out.mesh = make_sheet(16, 0.1);
  } else if (name == "sheet-256") {
    out.mesh = make_sheet(256, 0.1);
  } else if (name == "knee-tibia" || name == "knee-all") {
#ifdef HAPSIM_BENCH_HAVE_MESH_IO
    if (!knee_available(data_dir)) {
      throw Error("--meshes " + name,
                  "needs the knee data (knee_vhf_left/stl) in the data folder ($HAPSIM_DATA or "
                  "../shared/data); it was not found");
    }
    const std::filesystem::path folder = *data_dir / kKneeFolder;
    MeshLoadOptions options;
    options.scale = 1e-3;  // the VHF knee is in millimetres
    if (name == "knee-tibia") {
      out.mesh = load_mesh(folder / kKneeTibia, options);
    } else {
      std::vector<std::filesystem::path> files;
      for (const auto& entry : std::filesystem::directory_iterator(folder)) {
        if (entry.path().extension() == ".stl") {
          files.push_back(entry.path());
        }
      }
      std::sort(files.begin(), files.end());
      for (const auto& file : files) {
        out.mesh.append(load_mesh(file, options));
      }
    }
#else
    (void)data_dir;
    throw Error("--meshes " + name, "this build has no mesh loader yet");
#endif
  } else {
    std::string known;
    for (const auto& n : all_collision_mesh_names()) {
      known += (known.empty() ? "" : ", ") + n;
    }
    throw Error("--meshes " + name, "unknown mesh; expected one of " + known);
  }
  return out;
}

std::vector<Vec3> make_workload_points(const TriangleMesh& mesh, Workload workload,
                                       std::size_t count, std::uint64_t seed) {
  Reference reference(mesh);
  return workload_points(reference, workload, count, seed);
}

std::vector<std::string> all_method_names() {
  return {"hapsim-exact", "hapsim-spheretree", "hapsim-contact-radius", "cgal", "cgal-hint", "fcl",
          "embree"};
}

std::vector<std::string> available_methods() {
  const std::vector<std::string> oracles = oracle::available_oracles();
  std::vector<std::string> names;
  for (const std::string& name : all_method_names()) {
    const bool built =
#ifdef HAPSIM_BENCH_HAVE_MESH_BVH
        name == "hapsim-exact" || name == "hapsim-contact-radius" ||
#endif
#ifdef HAPSIM_BENCH_HAVE_SPHERE_TREE
        name == "hapsim-spheretree" ||
#endif
        std::find(oracles.begin(), oracles.end(), name) != oracles.end();
    if (built) {
      names.push_back(name);
    }
  }
  return names;
}

std::unique_ptr<BenchMethod> make_method(const std::string& name, const TriangleMesh& mesh) {
#ifdef HAPSIM_BENCH_HAVE_MESH_BVH
  if (name == "hapsim-exact" || name == "hapsim-contact-radius") {
    return std::make_unique<HapsimMethod>(name, std::make_unique<MeshBvh>(mesh),
                                          name == "hapsim-contact-radius");
  }
#endif
#ifdef HAPSIM_BENCH_HAVE_SPHERE_TREE
  if (name == "hapsim-spheretree") {
    return std::make_unique<HapsimMethod>(name, std::make_unique<SphereTree>(mesh), false);
  }
#endif
  if (auto oracle = oracle::make_oracle(name, mesh)) {
    return std::make_unique<OracleMethod>(std::move(oracle));
  }
  const auto all = all_method_names();
  std::string built;
  for (const auto& n : available_methods()) {
    built += (built.empty() ? "" : ", ") + n;
  }
  throw Error("--methods " + name, std::string(std::find(all.begin(), all.end(), name) != all.end()
                                                   ? "not built in this binary"
                                                   : "unknown method") +
                                       "; available: " + built);
}

std::vector<CollisionRow> run_collision_bench(const CollisionBenchOptions& options) {
  const std::vector<std::string> meshes =
      options.meshes.empty() ? collision_mesh_names(options.quick, options.data_dir)
                             : options.meshes;
  const std::vector<std::string> methods =
      options.methods.empty() ? available_methods() : options.methods;
  const std::size_t queries = options.queries != 0 ? options.queries : options.quick ? 4000 : 20000;
  const std::size_t warmup =
      options.warmup != 0 ? options.warmup : std::min<std::size_t>(1000, queries / 4);

  // Progress: per mesh, one unit for the mesh and workloads, then per method one for the build
  // and one per workload.
  const double units_per_mesh = 1.0 + static_cast<double>(methods.size()) *
                                          (1.0 + static_cast<double>(options.workloads.size()));
  const double total_units = units_per_mesh * static_cast<double>(meshes.size());
  double done = 0.0;
  const auto progress = [&](const std::string& label) {
    report_progress(options.progress, label, std::min(1.0, done / total_units));
  };

  std::vector<CollisionRow> rows;
  for (const std::string& mesh_name : meshes) {
    progress(mesh_name + ": mesh and query points");
    const BenchMesh bench_mesh = make_bench_mesh(mesh_name, options.data_dir);
    const TriangleMesh& mesh = bench_mesh.mesh;
    std::vector<std::vector<Vec3>> points;
    std::vector<std::vector<double>> reference_distances;
    {
      Reference reference(mesh);
      for (const Workload workload : options.workloads) {
        points.push_back(workload_points(reference, workload, queries, options.seed));
        std::vector<double> distances;
        distances.reserve(queries);
        for (const Vec3& p : points.back()) {
          distances.push_back((reference.closest(p).point - p).norm());
        }
        reference_distances.push_back(std::move(distances));
      }
    }
    done += 1.0;
    for (const std::string& method_name : methods) {
      progress(mesh_name + ": build " + method_name + " (" + format_count(mesh.triangle_count()) +
               " triangles)");
      const Stopwatch build_watch;
      const std::unique_ptr<BenchMethod> method = make_method(method_name, mesh);
      const double build_ms = build_watch.elapsed_ms();
      done += 1.0;
      for (std::size_t w = 0; w < options.workloads.size(); ++w) {
        if (options.stop != nullptr && options.stop->load(std::memory_order_relaxed)) {
          compute_ratios(rows);
          return rows;
        }
        progress(mesh_name + ": " + to_string(options.workloads[w]) + " " + method_name);
        Timing timing = time_queries(*method, points[w], warmup);
        CollisionRow row;
        row.mesh = mesh_name;
        row.triangles = mesh.triangle_count();
        row.workload = to_string(options.workloads[w]);
        row.method = method_name;
        row.median_ns = timing.median_ns;
        row.p99_ns = timing.p99_ns;
        row.mean_ns = timing.mean_ns;
        row.build_ms = build_ms;
        row.bytes_per_triangle =
            static_cast<double>(method->memory_bytes()) /
            static_cast<double>(std::max<std::size_t>(1, mesh.triangle_count()));
        row.query_count = points[w].size();
        check_against_reference(method_name, timing.distances, reference_distances[w], row);
        rows.push_back(std::move(row));
        done += 1.0;
      }
    }
  }
  report_progress(options.progress, "done", 1.0);
  compute_ratios(rows);
  return rows;
}

namespace {
bool is_library_method(const std::string& method) {
  return method.rfind("hapsim-", 0) != 0;
}
}  // namespace

void compute_ratios(std::vector<CollisionRow>& rows) {
  std::map<std::pair<std::string, std::string>, std::pair<double, double>> fastest;
  for (const CollisionRow& row : rows) {
    if (!is_library_method(row.method)) {
      continue;
    }
    auto [it, inserted] = fastest.try_emplace({row.mesh, row.workload}, row.median_ns, row.p99_ns);
    if (!inserted) {
      it->second.first = std::min(it->second.first, row.median_ns);
      it->second.second = std::min(it->second.second, row.p99_ns);
    }
  }
  for (CollisionRow& row : rows) {
    const auto it = fastest.find({row.mesh, row.workload});
    if (it == fastest.end()) {
      row.ratio_to_fastest_library = 0.0;
      row.p99_ratio_to_fastest_library = 0.0;
      continue;
    }
    row.ratio_to_fastest_library = it->second.first > 0.0 ? row.median_ns / it->second.first : 0.0;
    row.p99_ratio_to_fastest_library =
        it->second.second > 0.0 ? row.p99_ns / it->second.second : 0.0;
  }
}

std::string format_table(const std::vector<CollisionRow>& rows_in_run_order) {
  // Rows arrive method by method; a table compares methods, so group by mesh and workload
  // (each in order of first appearance) and keep the run order of methods inside a group.
  std::vector<std::string> keys;
  for (const CollisionRow& row : rows_in_run_order) {
    const std::string key = row.mesh + "/" + row.workload;
    if (std::find(keys.begin(), keys.end(), key) == keys.end()) {
      keys.push_back(key);
    }
  }
  std::vector<CollisionRow> rows;
  rows.reserve(rows_in_run_order.size());
  for (const std::string& key : keys) {
    for (const CollisionRow& row : rows_in_run_order) {
      if (row.mesh + "/" + row.workload == key) {
        rows.push_back(row);
      }
    }
  }
  std::ostringstream out;
  char line[256];
  const std::size_t n = rows.empty() ? 0 : rows.front().query_count;
  std::snprintf(line, sizeof line,
                "Closest-point queries: per-query ns (each query timed alone with steady_clock, "
                "%.0f ns timer overhead subtracted), %zu queries per row after warm-up.\n",
                timer_overhead_ns(), n);
  out << line;
  out << "x lib = median (p99) / the fastest library's median (p99) on the same mesh and workload;"
         " < 1 is faster.\n"
         "build = wall ms to construct from a TriangleMesh (embree builds on all cores; the others "
         "on one).\n"
         "B/tri = structure bytes per triangle: hapsim excludes the mesh; fcl and embree include "
         "their own mesh copy (embree: float).\n"
         "hapsim-contact-radius = MeshBvh::contact_within(p, 2 mm). embree prunes in float, "
         "refines in double. err = max |d - exact| (m).\n";
  std::string group;
  for (const CollisionRow& row : rows) {
    const std::string key = row.mesh + "/" + row.workload;
    if (key != group) {
      group = key;
      std::snprintf(line, sizeof line, "\n%s (%s triangles), %s\n", row.mesh.c_str(),
                    format_count(row.triangles).c_str(), row.workload.c_str());
      out << line;
      std::snprintf(line, sizeof line, "  %-22s %10s %10s %9s %9s %10s %9s %9s %5s\n", "method",
                    "median ns", "p99 ns", "x lib", "x lib p99", "build ms", "B/tri", "err", "bad");
      out << line;
    }
    std::snprintf(line, sizeof line,
                  "  %-22s %10.0f %10.0f %8.2fx %8.2fx %10.1f %9.1f %9.1e %5zu\n",
                  row.method.c_str(), row.median_ns, row.p99_ns, row.ratio_to_fastest_library,
                  row.p99_ratio_to_fastest_library, row.build_ms, row.bytes_per_triangle,
                  row.max_distance_error, row.mismatches);
    out << line;
  }
  return out.str();
}

nlohmann::json rows_to_json(const std::vector<CollisionRow>& rows) {
  nlohmann::json array = nlohmann::json::array();
  for (const CollisionRow& row : rows) {
    array.push_back({
        {"mesh", row.mesh},
        {"triangles", row.triangles},
        {"workload", row.workload},
        {"method", row.method},
        {"median_ns", row.median_ns},
        {"p99_ns", row.p99_ns},
        {"build_ms", row.build_ms},
        {"bytes_per_triangle", row.bytes_per_triangle},
        {"mean_ns", row.mean_ns},
        {"query_count", row.query_count},
        {"ratio_to_fastest_library", row.ratio_to_fastest_library},
        {"p99_ratio_to_fastest_library", row.p99_ratio_to_fastest_library},
        {"max_distance_error_m", std::isfinite(row.max_distance_error)
                                     ? nlohmann::json(row.max_distance_error)
                                     : nlohmann::json(nullptr)},
        {"mismatches", row.mismatches},
    });
  }
  return array;
}

}  // namespace hapsim::bench
