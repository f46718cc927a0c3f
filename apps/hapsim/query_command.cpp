// `hapsim query MESH --points FILE.csv --method exact|spheretree|knee`: signed distance, closest
// point, normal and triangle for each point, in the input's order and units. An approximate
// method (the knee paper's) also reports its error against the exact query on the same points.
#include "checked_output.h"
#include "commands.h"
#include "points_csv.h"

#include "hapsim/collision/knee_error.h"
#include "hapsim/collision/knee_index.h"
#include "hapsim/collision/mesh_bvh.h"
#include "hapsim/collision/sphere_tree.h"
#include "hapsim/core/statistics.h"
#include "hapsim/core/stopwatch.h"
#include "hapsim/geometry/mesh_argument.h"

#include <nlohmann/json.hpp>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <memory>
#include <optional>

namespace hapsim::app {
namespace {

struct QueryOptions {
  std::string mesh;
  std::string points;
  std::string method = "exact";
  double scale = 1.0;
  std::string out_path;
  std::string json_path;
};

// A straight probe path through the built-in meshes (metres), 0.05 mm steps: enters and leaves
// the body, like a palpating finger.
std::vector<Vec3> builtin_probe_path() {
  std::vector<Vec3> points;
  const Vec3 from(-0.08, 0.01, 0.005);
  const Vec3 to(0.08, 0.01, 0.005);
  const int steps = static_cast<int>(std::lround((to - from).norm() / 0.05e-3));
  for (int i = 0; i <= steps; ++i) {
    points.push_back(from + (to - from) * (static_cast<double>(i) / steps));
  }
  return points;
}

void write_row(std::FILE* f, const Vec3& p, const SurfacePoint& s, double to_units) {
  std::fprintf(f, "%.17g,%.17g,%.17g,%.17g,%.17g,%.17g,%.17g,%.17g,%.17g,%.17g,%u\n", p.x(), p.y(),
               p.z(), s.signed_distance * to_units, s.point.x() * to_units, s.point.y() * to_units,
               s.point.z() * to_units, s.normal.x(), s.normal.y(), s.normal.z(), s.triangle);
}

void run_query(const QueryOptions& opt) {
  if (opt.method != "exact" && opt.method != "spheretree" && opt.method != "knee") {
    throw CommandError("--method: expected exact, spheretree or knee, got '" + opt.method + "'");
  }
  // Read the points before the (possibly slow) mesh load so a bad file fails fast.
  const std::vector<Vec3> points_units =
      opt.points == "builtin:probe-path" ? builtin_probe_path() : read_points_csv(opt.points);
  // Squared distances overflow from ~1e154 m on (the answer was inf and no triangle); nothing a
  // query is for lies that far, so a point beyond 1e9 m is a unit or column mix-up, said as such.
  constexpr double kMaxPointDistance_m = 1e9;
  for (std::size_t i = 0; i < points_units.size(); ++i) {
    const double farthest_m = (points_units[i] * opt.scale).cwiseAbs().maxCoeff();
    if (!(farthest_m <= kMaxPointDistance_m)) {
      char text[160];
      std::snprintf(text, sizeof text,
                    ": point %zu lies %.3g m from the origin along an axis; expected points within "
                    "%.0e m (a unit mix-up?)",
                    i + 1, farthest_m, kMaxPointDistance_m);
      throw CommandError(opt.points + text);
    }
  }
  MeshArgument arg = load_mesh_argument(opt.mesh, opt.scale);
  if (arg.mesh.empty()) {
    throw CommandError(opt.mesh + ": the mesh has no triangles");
  }
  std::unique_ptr<ProximityQuery> query;
  if (opt.method == "exact") {
    query = std::make_unique<MeshBvh>(arg.mesh);
  } else if (opt.method == "spheretree") {
    query = std::make_unique<SphereTree>(arg.mesh);
  } else {
    query = std::make_unique<KneeIndex>(arg.mesh);
  }

  OutputFile out_file("--out", opt.out_path);
  std::FILE* out = out_file.get();
  std::fprintf(out, "x,y,z,signed_distance,cx,cy,cz,nx,ny,nz,triangle\n");
  const double to_units = 1.0 / opt.scale;
  QueryHint hint;  // consecutive points are usually close: last answer bounds the next
  std::size_t inside = 0;
  double min_distance = kInf;
  double max_distance = -kInf;
  std::vector<double> query_ns;
  query_ns.reserve(points_units.size());
  for (const Vec3& p_units : points_units) {
    const Vec3 p_m = p_units * opt.scale;
    const Stopwatch watch;
    const SurfacePoint s = query->closest_point(p_m, &hint);
    query_ns.push_back(watch.elapsed_s() * 1e9);
    write_row(out, p_units, s, to_units);
    inside += s.inside() ? 1 : 0;
    min_distance = std::min(min_distance, s.signed_distance);
    max_distance = std::max(max_distance, s.signed_distance);
  }
  out_file.commit();
  const SampleSummary cost = summarize_samples(query_ns);
  const double median_ns = cost.p50;
  const double p99_ns = cost.p99;
  // The summary goes to stderr when the CSV is on stdout, so pipes stay clean.
  std::FILE* info = out_file.info();
  std::fprintf(info,
               "hapsim query: %zu points vs %s (%zu triangles, method %s): %zu inside, signed "
               "distance %.4g .. %.4g mm; %.0f ns median, %.0f ns p99 per query\n",
               points_units.size(), arg.name.c_str(), arg.mesh.triangle_count(), opt.method.c_str(),
               inside, min_distance * 1e3, max_distance * 1e3, median_ns, p99_ns);
  // An approximate method's error against the exact query, on the points within kErrorBand_m of
  // the surface on either side (the knee method answers only near the body; a point deep inside
  // is not "near the surface" either).
  constexpr double kErrorBand_m = 0.01;
  std::optional<ApproximationError> error;
  std::size_t beyond_band = 0;
  if (opt.method == "knee") {
    const MeshBvh exact(arg.mesh);
    std::vector<Vec3> near_m;
    near_m.reserve(points_units.size());
    for (const Vec3& p : points_units) {
      const Vec3 p_m = p * opt.scale;
      const SurfacePoint sp = exact.closest_point(p_m);
      if (sp.found() && std::abs(sp.signed_distance) <= kErrorBand_m) {
        near_m.push_back(p_m);
      } else {
        ++beyond_band;
      }
    }
    error = measure_approximation_error(*query, exact, near_m, kErrorBand_m);
    std::fprintf(info,
                 "error vs exact on the %zu points within %.0f mm of the surface, inside or out "
                 "(%zu deeper inside or farther out not compared): |distance error| mean %.3f "
                 "mm, p95 %.3f mm, max %.3f mm; %zu answered; %zu missed contact(s) of %zu, %zu "
                 "false contact(s)\n",
                 error->points, kErrorBand_m * 1e3, beyond_band, error->mean_abs_error_m * 1e3,
                 error->p95_abs_error_m * 1e3, error->max_abs_error_m * 1e3, error->answered,
                 error->misses, error->reference_contacts, error->false_contacts);
  }
  if (!opt.json_path.empty()) {
    const nlohmann::json j = {{"mesh", arg.name},
                              {"triangles", arg.mesh.triangle_count()},
                              {"method", opt.method},
                              {"points", points_units.size()},
                              {"inside", inside},
                              {"min_signed_distance_m", min_distance},
                              {"max_signed_distance_m", max_distance},
                              {"median_ns", median_ns},
                              {"p99_ns", p99_ns},
                              {"mean_ns", cost.mean}};
    nlohmann::json full = j;
    if (error) {
      full["error_vs_exact"] = {{"band_m", kErrorBand_m},
                                {"band_sides", "inside and outside"},
                                {"points", error->points},
                                {"not_compared", beyond_band},
                                {"answered", error->answered},
                                {"mean_abs_error_m", error->mean_abs_error_m},
                                {"p95_abs_error_m", error->p95_abs_error_m},
                                {"max_abs_error_m", error->max_abs_error_m},
                                {"reference_contacts", error->reference_contacts},
                                {"misses", error->misses},
                                {"false_contacts", error->false_contacts}};
    }
    write_json_file("--json", opt.json_path, full);
  }
}

}  // namespace

void add_query_command(CLI::App& app) {
  auto opt = std::make_shared<QueryOptions>();
  CLI::App* cmd = app.add_subcommand(
      "query", "Signed distance, closest point, normal and triangle for each point of a CSV");
  cmd->add_option("mesh", opt->mesh, "Mesh file or builtin:NAME (see hapsim info --help)")
      ->required();
  cmd->add_option("--points", opt->points,
                  "CSV of x,y,z rows in mesh units (header optional), or builtin:probe-path")
      ->required();
  cmd->add_option(
         "--method", opt->method,
         "exact (BVH), spheretree or knee (the knee paper's groups; also reports its error "
         "against exact)")
      ->capture_default_str();
  cmd->add_option("--scale", opt->scale, "Mesh units to metres (e.g. 0.001 for millimetres)")
      ->check(CLI::PositiveNumber);
  cmd->add_option("--out", opt->out_path, "Write the CSV here instead of standard output");
  cmd->add_option("--json", opt->json_path, "Also write a summary as JSON to this file");
  cmd->callback([opt] { run_query(*opt); });
}

}  // namespace hapsim::app
