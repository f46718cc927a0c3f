// `hapsim simplify MESH --target-vertices N --out FILE`: a closed mesh simplified to a vertex
// budget (meshoptimizer), checked closed and valid, with the Hausdorff distance the
// simplification caused measured both ways by the exact closest-point query. The output file is
// written in the input's units.
#include "commands.h"
#include "json_output.h"

#include "hapsim/collision/hausdorff.h"
#include "hapsim/geometry/mesh_argument.h"
#include "hapsim/geometry/mesh_io.h"
#include "hapsim/geometry/mesh_simplify.h"
#include "hapsim/geometry/mesh_validation.h"

#include <cstdio>
#include <filesystem>
#include <memory>

namespace hapsim::app {
namespace {

struct SimplifyOptions {
  std::string mesh;
  long long target_vertices = 0;
  std::string out_path;
  double scale = 1.0;
  std::string json_path;
};

nlohmann::json to_json(const OneSidedHausdorff& h) {
  return {{"sampled_m", h.sampled_m}, {"bound_m", h.bound_m}, {"samples", h.samples}};
}

void run_simplify(const SimplifyOptions& opt) {
  if (opt.target_vertices <= 0) {
    throw CommandError("--target-vertices: must be a positive count, got " +
                       std::to_string(opt.target_vertices));
  }
  if (!is_mesh_file_supported(opt.out_path)) {
    throw CommandError("--out " + opt.out_path +
                       ": unknown mesh extension (use .stl, .ply, .obj, .gltf or .glb)");
  }
  JsonOutput json(opt.json_path);
  // Loading welds exact duplicates (an STL's per-face corners), validates and repairs.
  const MeshArgument arg = load_mesh_argument(opt.mesh, opt.scale);
  if (arg.mesh.empty()) {
    throw CommandError(opt.mesh + ": the mesh has no triangles");
  }
  const MeshReport source_report = validate_mesh(arg.mesh);
  if (!source_report.closed) {
    throw CommandError(opt.mesh + ": not a closed surface (" + source_report.summary() +
                       "); simplify keeps closed surfaces closed and needs one");
  }
  MeshSimplifyOptions options;
  options.target_vertices = static_cast<std::size_t>(opt.target_vertices);
  const MeshSimplifyResult result = simplify_mesh(arg.mesh, options);
  if (!result.valid) {
    throw CommandError(opt.mesh + ": no valid closed result at " +
                       std::to_string(opt.target_vertices) + " vertices after " +
                       std::to_string(result.attempts) + " attempts (" + result.problem + ")");
  }
  const HausdorffDistance h = hausdorff_distance(result.mesh, arg.mesh);
  MeshSaveOptions save;
  save.scale = 1.0 / opt.scale;
  try {
    save_mesh(opt.out_path, result.mesh, save);
  } catch (const Error& e) {
    throw CommandError("--out " + std::string(e.what()));  // e names the path
  }
  const MeshReport report = validate_mesh(result.mesh);
  const double to_mm = 1e3;
  std::printf("source       %s: %zu vertices, %zu triangles\n", arg.name.c_str(),
              result.source_vertices, result.source_triangles);
  std::printf("simplified   %s: %s\n", opt.out_path.c_str(), report.summary().c_str());
  std::printf(
      "hausdorff    %.3f mm (simplified -> source %.3f mm, source -> simplified %.3f mm; "
      "exact closest-point query; upper bound %.3f mm)\n",
      h.sampled_m() * to_mm, h.a_to_b.sampled_m * to_mm, h.b_to_a.sampled_m * to_mm,
      h.bound_m() * to_mm);
  if (json) {
    json.write({{"source", arg.name},
                {"out", opt.out_path},
                {"target_vertices", opt.target_vertices},
                {"source_vertices", result.source_vertices},
                {"source_triangles", result.source_triangles},
                {"vertices", result.mesh.vertex_count()},
                {"triangles", result.mesh.triangle_count()},
                {"attempts", result.attempts},
                {"closed", report.closed},
                {"hausdorff_m", h.sampled_m()},
                {"hausdorff_bound_m", h.bound_m()},
                {"simplified_to_source", to_json(h.a_to_b)},
                {"source_to_simplified", to_json(h.b_to_a)},
                {"validation", nlohmann::json::parse(report.to_json())}});
  }
}

}  // namespace

void add_simplify_command(CLI::App& app) {
  auto opt = std::make_shared<SimplifyOptions>();
  CLI::App* cmd = app.add_subcommand(
      "simplify",
      "Simplify a closed mesh to a vertex budget (meshoptimizer); report the Hausdorff distance");
  cmd->add_option("mesh", opt->mesh, "Mesh file or builtin:NAME (see hapsim info --help)")
      ->required();
  cmd->add_option("--target-vertices", opt->target_vertices,
                  "Largest number of vertices of the result")
      ->required();
  cmd->add_option("--out", opt->out_path, "Write the simplified mesh here (.stl, .ply, .obj, ...)")
      ->required();
  cmd->add_option("--scale", opt->scale,
                  "Mesh units to metres (e.g. 0.001 for millimetres); the output keeps the units")
      ->check(CLI::PositiveNumber);
  cmd->add_option("--json", opt->json_path, "Also write a summary as JSON to this file");
  cmd->callback([opt] { run_simplify(*opt); });
}

}  // namespace hapsim::app
