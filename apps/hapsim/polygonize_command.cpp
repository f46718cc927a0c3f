// `hapsim polygonize [--mesh FILE]... [--csg NODE.json] [--offset-m D] [--crop-min X,Y,Z
// --crop-max X,Y,Z] --cell-m H --out FILE`: a closed surface from signed distances — the union of
// closed meshes (each answered by the exact query: MeshBvh's signed distance) and a CSG solid
// (a NODE as in a scene file), grown by an offset and cut to a box, polygonised by marching
// tetrahedra. It derives the real knee's parts: a modelled femur (CSG), long muscles cut to the
// knee region, and a skin a few millimetres over everything (scripts/derive-knee.sh).
#include "commands.h"
#include "json_output.h"

#include "hapsim/collision/mesh_bvh.h"
#include "hapsim/core/disjoint_sets.h"
#include "hapsim/geometry/mesh_argument.h"
#include "hapsim/geometry/mesh_io.h"
#include "hapsim/geometry/mesh_simplify.h"
#include "hapsim/geometry/mesh_validation.h"
#include "hapsim/geometry/polygonizer.h"
#include "hapsim/scene/csg_reader.h"
#include "hapsim/scene/json_reader.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <memory>
#include <optional>
#include <sstream>
#include <unordered_map>

namespace hapsim::app {
namespace {

struct PolygonizeCommandOptions {
  std::vector<std::string> meshes;
  std::string csg_path;
  double offset_m = 0.0;
  std::string crop_min;
  std::string crop_max;
  double cell_m = 0.0;
  double scale = 1.0;
  std::string out_path;
  std::string json_path;
};

Vec3 parse_point(const std::string& text, const char* option, double scale) {
  std::stringstream in(text);
  Vec3 p;
  char comma = 0;
  if (!(in >> p.x() >> comma >> p.y() >> comma >> p.z()) || !p.allFinite() || !in.eof()) {
    throw CommandError(std::string(option) + ": expected X,Y,Z in mesh units, got '" + text + "'");
  }
  return p * scale;
}

// One closed mesh's exact signed distance, with its bounds to skip it where it cannot be nearest.
struct MeshField {
  TriangleMesh mesh;
  std::unique_ptr<MeshBvh> query;
  Box3 bounds;
};

double box_distance(const Box3& box, const Vec3& p) {
  return std::sqrt(box.squaredExteriorDistance(p));
}

// The union's signed distance: the smallest part distance. A part whose bounds are farther than
// the best so far cannot be nearer (outside every part, exact; inside one, its value wins).
SdfSample union_distance(const std::vector<MeshField>& parts, const Vec3& p) {
  SdfSample best;
  for (const MeshField& part : parts) {
    if (box_distance(part.bounds, p) >= best.distance_m) {
      continue;
    }
    const SurfacePoint s = part.query->closest_point(p);
    if (s.signed_distance < best.distance_m) {
      best.distance_m = s.signed_distance;
      best.gradient = s.normal;
    }
  }
  return best;
}

// The cut: intersect with an axis-aligned box (exact box distance inside and outside).
SdfSample box_sdf(const Box3& box, const Vec3& p) {
  const Vec3 c = box.center();
  const Vec3 h = 0.5 * box.sizes();
  const Vec3 q = (p - c).cwiseAbs() - h;
  SdfSample s;
  const Vec3 outside = q.cwiseMax(0.0);
  if (outside.squaredNorm() > 0.0) {
    s.distance_m = outside.norm();
    s.gradient = outside.cwiseProduct((p - c).cwiseSign()) / s.distance_m;
  } else {
    Eigen::Index axis = 0;
    s.distance_m = q.maxCoeff(&axis);
    s.gradient = Vec3::Zero();
    s.gradient[axis] = (p - c)[axis] >= 0.0 ? 1.0 : -1.0;
  }
  return s;
}

// Splits by shared vertices (union-find) and keeps the component of largest signed volume;
// returns how many components were dropped.
std::size_t keep_largest_component(TriangleMesh& mesh) {
  DisjointSets pieces(mesh.vertex_count());
  const auto find = [&](std::uint32_t v) { return pieces.find(v); };
  for (const TriangleIndices& t : mesh.triangles) {
    pieces.unite(t[0], t[1]);
    pieces.unite(t[0], t[2]);
  }
  std::unordered_map<std::uint32_t, double> volume;
  for (std::size_t t = 0; t < mesh.triangle_count(); ++t) {
    const auto c = mesh.corners(t);
    volume[find(mesh.triangles[t][0])] += c[0].dot(c[1].cross(c[2])) / 6.0;
  }
  if (volume.size() <= 1) {
    return 0;
  }
  const auto largest = std::max_element(volume.begin(), volume.end(), [](auto& a, auto& b) {
                         return a.second < b.second;
                       })->first;
  std::erase_if(mesh.triangles, [&](const TriangleIndices& t) { return find(t[0]) != largest; });
  mesh.remove_unused_vertices();
  return volume.size() - 1;
}

void run_polygonize(const PolygonizeCommandOptions& opt) {
  if (opt.meshes.empty() && opt.csg_path.empty()) {
    throw CommandError("give at least one --mesh or a --csg solid");
  }
  if (!(opt.cell_m > 0.0) || !std::isfinite(opt.cell_m)) {
    throw CommandError("--cell-m: must be a positive cell size in metres");
  }
  if (!std::isfinite(opt.offset_m)) {
    throw CommandError("--offset-m: must be a finite distance in metres");
  }
  if (opt.crop_min.empty() != opt.crop_max.empty()) {
    throw CommandError("--crop-min and --crop-max go together");
  }
  if (!is_mesh_file_supported(opt.out_path)) {
    throw CommandError("--out " + opt.out_path + ": unknown mesh extension");
  }
  JsonOutput json(opt.json_path);
  std::vector<MeshField> parts;
  Box3 bounds;
  for (const std::string& file : opt.meshes) {
    MeshField part;
    part.mesh = load_mesh_argument(file, opt.scale).mesh;
    const MeshReport report = validate_mesh(part.mesh);
    if (!report.closed) {
      throw CommandError(file + ": not a closed surface (" + report.summary() +
                         "); its signed distance has no inside");
    }
    part.bounds = part.mesh.bounds();
    bounds.extend(part.bounds);
    parts.push_back(std::move(part));
  }
  for (MeshField& part : parts) {
    part.query = std::make_unique<MeshBvh>(part.mesh);  // after the moves: it keeps a reference
  }
  std::optional<CsgSolid> solid;
  if (!opt.csg_path.empty()) {
    std::ifstream in(opt.csg_path);
    if (!in) {
      throw CommandError("--csg " + opt.csg_path + ": cannot read the file");
    }
    const JsonReader reader(opt.csg_path);
    JsonReader::Json j;
    try {
      j = JsonReader::Json::parse(in);
    } catch (const std::exception& e) {
      throw CommandError("--csg " + opt.csg_path + ": not JSON (" + e.what() + ")");
    }
    // The node is in metres, like a scene's; scale it to the meshes' frame by --scale only when
    // writing, so mixed inputs share one frame (metres).
    solid = read_csg_node(reader, j, "");
    bounds.extend(solid->bounds());
  }
  std::optional<Box3> crop;
  if (!opt.crop_min.empty()) {
    crop = Box3(parse_point(opt.crop_min, "--crop-min", opt.scale),
                parse_point(opt.crop_max, "--crop-max", opt.scale));
    if (crop->isEmpty()) {
      throw CommandError("--crop-min must be below --crop-max on every axis");
    }
  }
  const double offset_m = opt.offset_m;
  DistanceField field;
  field.evaluate = [&](const Vec3& p) {
    SdfSample s = union_distance(parts, p);
    if (solid) {
      const SdfSample c = solid->evaluate(p);
      if (c.distance_m < s.distance_m) {
        s = c;
      }
    }
    s.distance_m -= offset_m;
    if (crop) {
      const SdfSample b = box_sdf(*crop, p);
      if (b.distance_m > s.distance_m) {
        s = b;
      }
    }
    return s;
  };
  field.distance = [&](const Vec3& p) { return field.evaluate(p).distance_m; };
  bounds.min() -= Vec3::Constant(std::max(offset_m, 0.0));
  bounds.max() += Vec3::Constant(std::max(offset_m, 0.0));
  field.bounds = crop ? bounds.intersection(*crop) : bounds;
  // A cell coarser than half the shape meshes nothing of it, and the grid's padding (a cell each
  // side) once made a box 1e20 m across out of a 0.1 m one.
  const double longest_m = field.bounds.isEmpty() ? 0.0 : field.bounds.sizes().maxCoeff();
  if (opt.cell_m > 0.5 * longest_m) {
    char text[256];
    std::snprintf(text, sizeof text,
                  "--cell-m: %g m is coarser than the shape, whose largest extent is %g m; use at "
                  "most half of that (a few hundredths of it for a faithful surface)",
                  opt.cell_m, longest_m);
    throw CommandError(text);
  }
  // The grid is centred on the bounds: shift it off the crop planes by an odd fraction of a cell,
  // so no node lies exactly on a flat face (a vertex on a node makes a zero-area triangle).
  field.bounds.max() += Vec3(0.371, 0.293, 0.417) * opt.cell_m;

  PolygonizeOptions options;
  options.cell_size_m = opt.cell_m;
  options.gradient_normals = false;
  PolygonizeStats stats;
  TriangleMesh mesh = polygonize(field, options, &stats);
  // Overlapping parts can leave small pieces apart from the main surface (a pocket between
  // parts, a sliver of a cut): keep the component enclosing the most volume, and say so.
  const std::size_t dropped = keep_largest_component(mesh);
  if (dropped > 0) {
    std::printf("dropped      %zu smaller component(s), kept the largest\n", dropped);
  }
  // Where a vertex landed on (or next to) a grid node the polygoniser keeps zero-area triangles
  // to stay closed; collapsing their shortest edges removes them and keeps the mesh closed.
  const std::size_t collapsed = collapse_degenerate_triangles(mesh);
  if (collapsed > 0) {
    std::printf("collapsed    %zu zero-area triangle edge(s)\n", collapsed);
  }
  const MeshRepairStats repaired = repair_mesh(mesh, ValidationPolicy::repair_all());
  if (repaired.any()) {
    std::printf("repaired     %s\n", repaired.summary().c_str());
  }
  const MeshReport report = validate_mesh(mesh);
  if (!report.closed || report.has_defects()) {
    throw CommandError(opt.out_path + ": the surface is not a valid closed mesh (" +
                       report.summary() + "); try a smaller --cell-m");
  }
  MeshSaveOptions save;
  save.scale = 1.0 / opt.scale;
  try {
    save_mesh(opt.out_path, mesh, save);
  } catch (const Error& e) {
    throw CommandError("--out " + std::string(e.what()));  // e names the path
  }
  std::printf("polygonized  %s: %s (cell %.3g mm, %d x %d x %d nodes)\n", opt.out_path.c_str(),
              report.summary().c_str(), stats.cell_size_m * 1e3, stats.grid_nodes[0],
              stats.grid_nodes[1], stats.grid_nodes[2]);
  if (json) {
    json.write({{"out", opt.out_path},
                {"vertices", mesh.vertex_count()},
                {"triangles", mesh.triangle_count()},
                {"cell_m", stats.cell_size_m},
                {"offset_m", offset_m},
                {"validation", nlohmann::json::parse(report.to_json())}});
  }
}

}  // namespace

void add_polygonize_command(CLI::App& app) {
  auto opt = std::make_shared<PolygonizeCommandOptions>();
  CLI::App* cmd = app.add_subcommand(
      "polygonize",
      "A closed surface from the union of closed meshes and a CSG solid, grown by an offset and "
      "cut to a box (marching tetrahedra on exact signed distances)");
  cmd->add_option("--mesh", opt->meshes, "A closed mesh of the union (repeatable)");
  cmd->add_option("--csg", opt->csg_path, "A CSG solid: one NODE as in a scene file, metres");
  cmd->add_option("--offset-m", opt->offset_m,
                  "Grow the union by this much, metres (a skin); negative shrinks it");
  cmd->add_option("--crop-min", opt->crop_min, "Cut to the box from X,Y,Z (mesh units) ...");
  cmd->add_option("--crop-max", opt->crop_max, "... to X,Y,Z (mesh units)");
  cmd->add_option("--cell-m", opt->cell_m, "Grid cell, metres")->required();
  cmd->add_option("--scale", opt->scale,
                  "Mesh units to metres (0.001 for millimetres); the output is in mesh units")
      ->check(CLI::PositiveNumber);
  cmd->add_option("--out", opt->out_path, "Write the surface here (.stl, .ply, .obj, ...)")
      ->required();
  cmd->add_option("--json", opt->json_path, "Also write a summary as JSON to this file");
  cmd->callback([opt] { run_polygonize(*opt); });
}

}  // namespace hapsim::app
