// `hapsim info MESH`: counts, validation, bounds, area and volume, and the cost and quality of
// both acceleration structures built over it. On a tet mesh (.msh, .node/.ele, .vtk): counts,
// regions, bounds, volume and shape quality; an invalid one is refused (exit 2, one line).
#include "checked_output.h"
#include "commands.h"

#include "hapsim/collision/mesh_bvh.h"
#include "hapsim/collision/sphere_tree.h"
#include "hapsim/geometry/mesh_argument.h"
#include "hapsim/geometry/mesh_validation.h"
#include "hapsim/geometry/tet_mesh.h"
#include "hapsim/geometry/tet_mesh_io.h"

#include <nlohmann/json.hpp>

#include <cstdio>
#include <fstream>
#include <iostream>
#include <map>
#include <memory>

namespace hapsim::app {
namespace {

// A triangle mesh larger than this (in metres, read with no --scale) gets a unit hint: no body a
// haptic scene holds is 5 m across, and millimetres read as metres are 1000 times too large.
constexpr double kUnitHintLargestM = 5.0;

struct InfoOptions {
  std::string mesh;
  double scale = 1.0;
  std::string json_path;
};

nlohmann::json vec_json(const Vec3& v) {
  return {v.x(), v.y(), v.z()};
}

// A tet mesh: read (which validates it: a bad element ends the command with the file, line and
// element), then described.
void run_tet_info(const InfoOptions& opt) {
  TetMesh mesh = read_tet_mesh(opt.mesh);
  mesh.scale(opt.scale);
  const TetBoundary boundary = tet_boundary(mesh);
  const TetMeshQuality q = tet_mesh_quality(mesh);
  std::map<std::int32_t, std::size_t> region_tets;
  for (std::size_t t = 0; t < mesh.tet_count(); ++t) {
    ++region_tets[mesh.region(t)];
  }
  const Box3 box = mesh.bounds();
  const Vec3 lo_mm = box.min() * 1e3;
  const Vec3 hi_mm = box.max() * 1e3;
  const Vec3 size_mm = hi_mm - lo_mm;

  std::printf("tet mesh     %s (x%g to metres)\n", opt.mesh.c_str(), opt.scale);
  std::printf("size         %zu nodes, %zu tetrahedra, %zu boundary triangles\n", mesh.node_count(),
              mesh.tet_count(), boundary.surface.triangle_count());
  std::string regions;
  for (const auto& [region, count] : region_tets) {
    regions += (regions.empty() ? "" : ", ") + std::to_string(region) + ": " +
               std::to_string(count) + (count == 1 ? " tet" : " tets");
  }
  std::printf("regions      %zu (%s)\n", region_tets.size(), regions.c_str());
  std::printf("bounds       [%.3f, %.3f, %.3f] .. [%.3f, %.3f, %.3f] mm (%.3f x %.3f x %.3f mm)\n",
              lo_mm.x(), lo_mm.y(), lo_mm.z(), hi_mm.x(), hi_mm.y(), hi_mm.z(), size_mm.x(),
              size_mm.y(), size_mm.z());
  std::printf("volume       %.6g mm^3 (smallest tet %.4g mm^3)\n", q.total_volume_m3 * 1e9,
              q.min_volume_m3 * 1e9);
  std::printf("quality      dihedral %.2f to %.2f deg, max aspect ratio %.3g [1 = regular]\n",
              q.min_dihedral_deg, q.max_dihedral_deg, q.max_aspect_ratio);
  std::printf("             %zu inverted, %zu degenerate, %zu piece%s, %zu unused node%s\n",
              q.inverted, q.degenerate, q.components, q.components == 1 ? "" : "s", q.unused_nodes,
              q.unused_nodes == 1 ? "" : "s");

  if (!opt.json_path.empty()) {
    nlohmann::json j;
    j["tet_mesh"] = opt.mesh;
    j["scale"] = opt.scale;
    j["nodes"] = mesh.node_count();
    j["tets"] = mesh.tet_count();
    j["boundary_triangles"] = boundary.surface.triangle_count();
    j["boundary_nodes"] = boundary.surface.vertex_count();
    nlohmann::json regions_json = nlohmann::json::array();
    for (const auto& [region, count] : region_tets) {
      regions_json.push_back({{"region", region}, {"tets", count}});
    }
    j["regions"] = regions_json;
    j["bounds_m"] = {{"min", vec_json(box.min())}, {"max", vec_json(box.max())}};
    j["volume_m3"] = q.total_volume_m3;
    j["quality"] = {{"min_dihedral_deg", q.min_dihedral_deg},
                    {"max_dihedral_deg", q.max_dihedral_deg},
                    {"max_aspect_ratio", q.max_aspect_ratio},
                    {"min_volume_m3", q.min_volume_m3},
                    {"inverted", q.inverted},
                    {"degenerate", q.degenerate},
                    {"pieces", q.components},
                    {"unused_nodes", q.unused_nodes}};
    write_json_file("--json", opt.json_path, j);
  }
}

void run_info(const InfoOptions& opt) {
  if (is_tet_mesh_path(opt.mesh)) {
    run_tet_info(opt);
    return;
  }
  MeshArgument arg = load_mesh_argument(opt.mesh, opt.scale);
  const TriangleMesh& mesh = arg.mesh;
  if (mesh.empty()) {
    throw CommandError(opt.mesh + ": the mesh has no triangles");
  }
  const Box3 box = mesh.bounds();
  const double tri = static_cast<double>(mesh.triangle_count());

  const MeshBvh bvh(mesh);
  const SphereTree tree(mesh);
  const BvhStats& b = bvh.stats();
  const SphereTreeStats& s = tree.stats();

  const Vec3 lo_mm = box.min() * 1e3;
  const Vec3 hi_mm = box.max() * 1e3;
  const Vec3 size_mm = hi_mm - lo_mm;
  std::printf("mesh         %s (x%g to metres)\n", arg.name.c_str(), arg.scale);
  std::printf("size         %zu triangles, %zu vertices\n", mesh.triangle_count(),
              mesh.vertex_count());
  std::printf("bounds       [%.3f, %.3f, %.3f] .. [%.3f, %.3f, %.3f] mm (%.3f x %.3f x %.3f mm)\n",
              lo_mm.x(), lo_mm.y(), lo_mm.z(), hi_mm.x(), hi_mm.y(), hi_mm.z(), size_mm.x(),
              size_mm.y(), size_mm.z());
  // An open mesh encloses nothing: its "volume" would be a number that depends on where the
  // origin is. Say why there is none instead.
  const MeshReport report = validate_mesh(mesh);
  if (report.closed) {
    std::printf("surface      %.4g mm^2, enclosed volume %.6g mm^3\n", mesh.surface_area() * 1e6,
                mesh.signed_volume() * 1e9);
  } else {
    std::printf(
        "surface      %.4g mm^2, no enclosed volume: the mesh is open (%zu edges with one "
        "triangle)\n",
        mesh.surface_area() * 1e6, report.open_edges);
  }
  // Scenes are in metres: a mesh tens of metres across is almost always millimetres read as
  // metres (a 42 m patella). Say so once, with the option that fixes it.
  const double largest_m = box.sizes().maxCoeff();
  std::string unit_hint;
  if (largest_m > kUnitHintLargestM && arg.scale == 1.0) {
    char text[200];
    std::snprintf(text, sizeof text,
                  "%.4g m across: if the file is in millimetres, give --scale 0.001 (%.4g mm)",
                  largest_m, largest_m);
    unit_hint = text;
    std::printf("units        %s\n", unit_hint.c_str());
  }
  if (!arg.validation.empty()) {
    std::printf("validation   %s\n", arg.validation.c_str());
  }
  std::printf("exact BVH    %zu nodes, %zu leaves, depth %zu, built in %.2f ms, %.1f B/triangle\n",
              b.nodes, b.leaves, b.depth, b.build_ms, static_cast<double>(b.memory_bytes) / tri);
  std::printf(
      "sphere tree  %zu nodes, %zu leaves, depth %zu, built in %.2f ms, %.1f B/triangle,\n"
      "             tightness %.3f (leaves) %.3f (inner) [1 = minimal spheres]\n",
      s.nodes, s.leaves, s.depth, s.build_ms, static_cast<double>(s.memory_bytes) / tri,
      s.leaf_tightness, s.inner_tightness);

  if (!opt.json_path.empty()) {
    nlohmann::json j;
    j["mesh"] = arg.name;
    j["scale"] = arg.scale;
    j["triangles"] = mesh.triangle_count();
    j["vertices"] = mesh.vertex_count();
    j["bounds_m"] = {{"min", vec_json(box.min())}, {"max", vec_json(box.max())}};
    j["surface_area_m2"] = mesh.surface_area();
    j["closed"] = report.closed;
    j["signed_volume_m3"] =
        report.closed ? nlohmann::json(mesh.signed_volume()) : nlohmann::json(nullptr);
    if (!unit_hint.empty()) {
      j["unit_hint"] = unit_hint;
    }
    if (!arg.validation_json.empty()) {
      j["validation"] = nlohmann::json::parse(arg.validation_json);
    }
    j["exact_bvh"] = {{"nodes", b.nodes},
                      {"leaves", b.leaves},
                      {"depth", b.depth},
                      {"build_ms", b.build_ms},
                      {"memory_bytes", b.memory_bytes}};
    j["sphere_tree"] = {{"nodes", s.nodes},
                        {"leaves", s.leaves},
                        {"depth", s.depth},
                        {"build_ms", s.build_ms},
                        {"memory_bytes", s.memory_bytes},
                        {"leaf_tightness", s.leaf_tightness},
                        {"inner_tightness", s.inner_tightness}};
    write_json_file("--json", opt.json_path, j);
  }
}

}  // namespace

void add_info_command(CLI::App& app) {
  auto opt = std::make_shared<InfoOptions>();
  CLI::App* cmd = app.add_subcommand(
      "info",
      "Describe a mesh: counts, validation, bounds, volume, acceleration structures (a tet mesh: "
      "counts, regions, volume, quality)");
  std::string builtins_help =
      "Mesh file (OBJ, STL, PLY, glTF, ...), a tet mesh (.msh Gmsh 4.1 ASCII, TetGen .node/.ele, "
      ".vtk legacy ASCII) or a built-in:";
  for (const auto& [name, description] : builtin_meshes()) {
    builtins_help += "\n  builtin:" + name + "  " + description;
  }
  cmd->add_option("mesh", opt->mesh, builtins_help)->required();
  cmd->add_option("--scale", opt->scale, "Mesh units to metres (e.g. 0.001 for millimetres)")
      ->check(CLI::PositiveNumber);
  cmd->add_option("--json", opt->json_path, "Also write the results as JSON to this file");
  cmd->callback([opt] { run_info(*opt); });
}

}  // namespace hapsim::app
