#include "hapsim/scene/geometry_reader.h"

#include "hapsim/core/error.h"
#include "hapsim/geometry/body_part_size.h"
#include "hapsim/geometry/mesh_io.h"
#include "hapsim/geometry/procedural.h"
#include "hapsim/geometry/tet_mesh_io.h"
#include "hapsim/scene/csg_reader.h"

#include <algorithm>
#include <cmath>
#include <iomanip>
#include <map>
#include <set>
#include <sstream>
#include <utility>

namespace hapsim {

using Json = JsonReader::Json;

void GeometryReader::check_sizes(const std::string& ptr, const std::vector<LoadedMesh>& meshes,
                                 double scale, const std::filesystem::path& folder) {
  struct Implausible {
    std::filesystem::path file;
    MeshScaleAdvice advice;
  };
  // Files one scale would fix share a warning: (too large, suggested scale) -> files.
  std::map<std::pair<bool, double>, std::vector<Implausible>> groups;
  std::vector<std::pair<bool, double>> order;
  for (const LoadedMesh& m : meshes) {
    std::error_code ec;
    if (!size_checked_.insert(std::filesystem::absolute(m.file, ec).lexically_normal()).second) {
      continue;  // once per file
    }
    const Box3 bounds = m.mesh->bounds();
    if (bounds.isEmpty()) {
      continue;
    }
    if (const auto advice = check_body_part_size(bounds.sizes().maxCoeff(), scale)) {
      const std::pair<bool, double> key{advice->too_large, advice->suggested_scale};
      if (groups[key].empty()) {
        order.push_back(key);
      }
      groups[key].push_back({m.file, *advice});
    }
  }
  const std::string where = r_.file().string() + ":" + ptr + ": ";
  for (const auto& key : order) {
    const std::vector<Implausible>& files = groups[key];
    if (files.size() == 1) {
      warnings_.push_back(where + files[0].file.string() + " " + describe(files[0].advice));
      continue;
    }
    // The most implausible file speaks for the group.
    const Implausible& worst = *std::max_element(
        files.begin(), files.end(), [](const Implausible& a, const Implausible& b) {
          return std::abs(std::log(a.advice.extent_m)) < std::abs(std::log(b.advice.extent_m));
        });
    std::string names;
    for (std::size_t i = 0; i < files.size() && i < 3; ++i) {
      names += (i == 0 ? "" : ", ") + files[i].file.filename().string();
    }
    if (files.size() > 3) {
      names += " and " + std::to_string(files.size() - 3) + " more";
    }
    std::ostringstream w;
    w << where << files.size() << " of " << meshes.size() << " mesh files in " << folder.string()
      << " (" << names << "); " << worst.file.filename().string() << " " << describe(worst.advice);
    warnings_.push_back(w.str());
  }
}

double GeometryReader::capped(double value, double cap, const std::string& ptr) {
  if (cap <= 0.0 || value <= cap) {
    return value;
  }
  std::ostringstream w;
  w << std::setprecision(6) << r_.file().string() << ":" << ptr << ": " << value << " lowered to "
    << cap << ", the most detail this load allows";
  warnings_.push_back(w.str());
  return cap;
}

// A volume for a FEM body: a generated block, or a tet mesh file (Gmsh, TetGen, VTK), with its
// boundary as the surface or a finer surface mesh embedded in it.
void GeometryReader::read_tets(const Json& j, const std::string& kp, const std::string& kind,
                               const std::string& body_name, BodyGeometry& body) {
  const Json& g = r_.object(j, kp, kind + " settings");
  TetMesh tets;
  std::optional<std::filesystem::path> surface_file;
  double scale = 1.0;
  if (kind == "tet_block") {
    r_.allow_keys(g, kp, {"size_m", "cells", "origin_m"});
    const Vec3 size = r_.vec3(r_.required(g, kp, "size_m"), JsonReader::at(kp, "size_m"), "m");
    if (!(size.minCoeff() > 0.0) || size.maxCoeff() > 100.0) {
      r_.fail(JsonReader::at(kp, "size_m"), "expected three sizes in (0, 100] m");
    }
    const std::string cp = JsonReader::at(kp, "cells");
    const Json& c = r_.array(r_.required(g, kp, "cells"), cp, "three cell counts");
    if (c.size() != 3) {
      r_.fail(cp, "expected three cell counts [nx, ny, nz]");
    }
    std::array<int, 3> cells{};
    double total = 1.0;
    for (std::size_t i = 0; i < 3; ++i) {
      const double n = r_.number(c[i], JsonReader::at(cp, i), "cells");
      if (!(n >= 1.0 && n <= 200.0) || n != std::floor(n)) {
        r_.fail(JsonReader::at(cp, i), "expected a whole number of cells in 1..200");
      }
      cells[i] = static_cast<int>(
          capped(n, r_.options().detail_caps.tet_block_cells, JsonReader::at(cp, i)));
      total *= cells[i];
    }
    if (6.0 * total > 2e6) {
      r_.fail(cp, "more than 2 million tetrahedra");
    }
    tets = make_tet_block(size, cells);
    if (g.contains("origin_m")) {
      tets.transform(
          Iso3(Eigen::Translation3d(r_.vec3(g["origin_m"], JsonReader::at(kp, "origin_m"), "m"))));
    }
    body.tets_source = r_.file().string() + ":" + kp;
  } else {
    r_.allow_keys(g, kp, {"file", "scale", "surface"});
    const std::string fp = JsonReader::at(kp, "file");
    const std::filesystem::path file = r_.existing_file(
        r_.required(g, kp, "file"), fp, "a tet mesh file (.msh, .node, .ele, .vtk)");
    scale = r_.number_in(g, kp, "scale", 1.0, 0.0, 1e6, "metres per file unit", true);
    try {
      tets = read_tet_mesh(file);
    } catch (const Error& e) {
      r_.fail(fp, "cannot load tet mesh " + e.where() + ": " + e.detail());
    }
    tets.scale(scale);
    if (g.contains("surface")) {
      surface_file = r_.existing_file(g["surface"], JsonReader::at(kp, "surface"),
                                      "a surface mesh file to embed in the tets");
    }
    body.tets_source = file.string();
  }
  SegmentDescription s;
  s.name = body_name;
  if (surface_file) {
    MeshLoadOptions lo;
    lo.scale = scale;
    try {
      s.mesh = load_mesh(*surface_file, lo);
    } catch (const Error& e) {
      r_.fail(JsonReader::at(kp, "surface"), "cannot load mesh " + e.where() + ": " + e.detail());
    }
    body.embedded_surface = true;
  } else {
    s.mesh = tet_boundary(tets).surface;
  }
  body.segments.push_back(std::move(s));
  body.tissues.emplace_back(std::nullopt);
  body.tets = std::make_shared<const TetMesh>(std::move(tets));
}

BodyGeometry GeometryReader::read(const Json& j, const std::string& ptr,
                                  const std::string& body_name) {
  r_.object(j, ptr, "a geometry");
  const char* kinds[] = {"procedural",  "box", "sphere",    "sheet",   "mesh",
                         "mesh_folder", "csg", "tet_block", "tet_mesh"};
  std::string kind;
  for (const char* k : kinds) {
    if (j.contains(k)) {
      if (!kind.empty()) {
        r_.fail(ptr, "expected exactly one geometry kind, got both '" + kind + "' and '" + k + "'");
      }
      kind = k;
    }
  }
  if (kind.empty()) {
    r_.fail(ptr,
            "expected one geometry kind: procedural, box, sphere, sheet, mesh, mesh_folder, csg, "
            "tet_block or tet_mesh");
  }
  const std::string kp = JsonReader::at(ptr, kind);
  BodyGeometry body;
  auto add = [&](std::string name, TriangleMesh mesh, std::optional<TissueKind> tissue,
                 bool two_sided = false) {
    SegmentDescription s;
    s.name = std::move(name);
    s.mesh = std::move(mesh);
    s.two_sided = two_sided;
    body.segments.push_back(std::move(s));
    body.tissues.push_back(tissue);
  };
  const ProgressFn& progress = r_.options().progress;
  const SceneDetailCaps& caps = r_.options().detail_caps;
  if (kind == "procedural") {
    r_.allow_keys(j, ptr, {"procedural", "resolution_scale", "include_skin"});
    r_.one_of(j["procedural"], kp, {"knee"});
    ProceduralKneeOptions o;
    o.resolution_scale = r_.number_in(j, ptr, "resolution_scale", 1.0, 0.25, 4.0, "", true);
    o.resolution_scale = capped(o.resolution_scale, caps.knee_resolution_scale,
                                JsonReader::at(ptr, "resolution_scale"));
    if (j.contains("include_skin")) {
      o.include_skin = r_.boolean(j["include_skin"], JsonReader::at(ptr, "include_skin"));
    }
    report_progress(progress, "scene: generating the procedural knee", 0.0);
    for (KneePart& part : make_procedural_knee(o)) {
      add(part.name, std::move(part.mesh), part.tissue);
    }
    return body;
  }
  if (kind == "csg") {
    report_progress(progress, "scene: polygonising the CSG solid of " + body_name, 0.0);
    CsgGeometry g = read_csg_geometry(r_, j, ptr, progress, caps.csg_grid_nodes);
    if (g.resolution_m != g.requested_resolution_m) {
      std::ostringstream w;
      w << std::setprecision(3) << r_.file().string() << ":" << ptr
        << ": the CSG display mesh is polygonised at " << g.resolution_m << " m, not "
        << g.requested_resolution_m << " m: this load allows at most " << caps.csg_grid_nodes
        << " grid nodes per solid";
      warnings_.push_back(w.str());
    }
    add(body_name, std::move(g.mesh), std::nullopt);
    body.segments.back().csg = std::move(g.solid);
    return body;
  }
  r_.allow_keys(j, ptr, {kind.c_str()});
  if (kind == "tet_block" || kind == "tet_mesh") {
    read_tets(j[kind], kp, kind, body_name, body);
    return body;
  }
  if (kind == "box") {
    const Json& b = r_.object(j[kind], kp, "box settings");
    r_.allow_keys(b, kp, {"half_extents_m"});
    const Vec3 h =
        r_.vec3(r_.required(b, kp, "half_extents_m"), JsonReader::at(kp, "half_extents_m"), "m");
    if (!(h.minCoeff() > 0.0)) {
      r_.fail(JsonReader::at(kp, "half_extents_m"), "expected half extents > 0 m");
    }
    add(body_name, make_box(h), std::nullopt);
  } else if (kind == "sphere") {
    const Json& s = r_.object(j[kind], kp, "sphere settings");
    r_.allow_keys(s, kp, {"radius_m", "segments"});
    if (!s.contains("radius_m")) {
      r_.fail(kp, "missing required key 'radius_m'");
    }
    const double r = r_.number_in(s, kp, "radius_m", 0.0, 0.0, 100.0, "m", true);
    const auto n = static_cast<int>(capped(r_.number_in(s, kp, "segments", 64, 8, 1024, ""),
                                           caps.sphere_segments, JsonReader::at(kp, "segments")));
    add(body_name, make_uv_sphere(r, n, n / 2), std::nullopt);
    body.segments.back().sphere = ExactSphere{Vec3::Zero(), r};  // contact: the sphere, exactly
  } else if (kind == "sheet") {
    const Json& s = r_.object(j[kind], kp, "sheet settings");
    r_.allow_keys(s, kp, {"size_m", "nodes_per_side"});
    if (!s.contains("size_m")) {
      r_.fail(kp, "missing required key 'size_m'");
    }
    const double size = r_.number_in(s, kp, "size_m", 0.0, 0.0, 100.0, "m", true);
    const auto n =
        static_cast<int>(capped(r_.number_in(s, kp, "nodes_per_side", 32, 2, 2048, ""),
                                caps.sheet_nodes_per_side, JsonReader::at(kp, "nodes_per_side")));
    add(body_name, make_sheet(n, size), std::nullopt, true);
  } else if (kind == "mesh" || kind == "mesh_folder") {
    const Json& m = r_.object(j[kind], kp, kind + " settings");
    if (kind == "mesh") {
      r_.allow_keys(m, kp, {"file", "scale"});
    } else {
      r_.allow_keys(m, kp, {"folder", "pattern", "scale", "strip_prefix", "strip_suffix"});
    }
    MeshLoadOptions lo;
    lo.scale = r_.number_in(m, kp, "scale", 1.0, 0.0, 1e6, "metres per file unit", true);
    auto load = [&](const std::filesystem::path& file, const std::string& p) {
      try {
        return load_mesh(file, lo);
      } catch (const Error& e) {
        r_.fail(p, "cannot load mesh " + e.where() + ": " + e.detail());
      }
    };
    if (kind == "mesh") {
      const std::string fp = JsonReader::at(kp, "file");
      const std::filesystem::path file =
          r_.path(r_.required(m, kp, "file"), fp, "a mesh file path");
      add(body_name, load(file, fp), std::nullopt);
      check_sizes(kp, {{file, &body.segments.back().mesh}}, lo.scale, {});
    } else {
      const std::string fp = JsonReader::at(kp, "folder");
      const std::filesystem::path folder =
          r_.path(r_.required(m, kp, "folder"), fp, "a folder path");
      std::error_code ec;  // a loop of symlinks, a name too long, an unreadable folder: said
      if (!std::filesystem::is_directory(folder, ec)) {
        r_.fail(fp, "expected a folder of mesh files; " + folder.string() + " is not a folder" +
                        (ec ? " (" + ec.message() + ")" : std::string()));
      }
      std::string pattern = "*.stl";
      if (m.contains("pattern")) {
        pattern = r_.nonempty_string(m["pattern"], JsonReader::at(kp, "pattern"),
                                     "a file pattern like *.stl");
        if (std::count(pattern.begin(), pattern.end(), '*') != 1) {
          r_.fail(JsonReader::at(kp, "pattern"),
                  "expected a file-name beginning, one '*' and an ending, e.g. '*.stl' or "
                  "'Bone_*.stl'");
        }
      }
      const std::size_t star = pattern.find('*');
      const std::string beginning = ascii_lower(pattern.substr(0, star));
      const std::string ending = ascii_lower(pattern.substr(star + 1));
      const std::string prefix =
          m.contains("strip_prefix")
              ? r_.string(m["strip_prefix"], JsonReader::at(kp, "strip_prefix"), "text")
              : "";
      const std::string suffix =
          m.contains("strip_suffix")
              ? r_.string(m["strip_suffix"], JsonReader::at(kp, "strip_suffix"), "text")
              : "";
      std::vector<std::filesystem::path> files;
      std::filesystem::directory_iterator it(folder, ec);
      for (; !ec && it != std::filesystem::directory_iterator(); it.increment(ec)) {
        const std::filesystem::directory_entry& entry = *it;
        const std::string name = ascii_lower(entry.path().filename().string());
        std::error_code entry_ec;
        if (entry.is_regular_file(entry_ec) && name.size() >= beginning.size() + ending.size() &&
            name.compare(0, beginning.size(), beginning) == 0 &&
            name.compare(name.size() - ending.size(), ending.size(), ending) == 0) {
          files.push_back(entry.path());
        }
      }
      if (ec) {
        r_.fail(fp, "cannot list the folder " + folder.string() + " (" + ec.message() + ")");
      }
      std::sort(files.begin(), files.end());
      if (files.empty()) {
        r_.fail(fp, "no file matching '" + pattern + "' in " + folder.string());
      }
      std::set<std::string> names;
      for (std::size_t i = 0; i < files.size(); ++i) {
        report_progress(progress, "scene: loading " + files[i].filename().string(),
                        static_cast<double>(i) / static_cast<double>(files.size()));
        std::string name = files[i].stem().string();
        if (!prefix.empty() && name.rfind(prefix, 0) == 0) {
          name = name.substr(prefix.size());
        }
        if (!suffix.empty() && name.size() > suffix.size() &&
            name.compare(name.size() - suffix.size(), suffix.size(), suffix) == 0) {
          name = name.substr(0, name.size() - suffix.size());
        }
        if (!names.insert(name).second) {
          r_.fail(fp, "two files give the segment name '" + name + "'");
        }
        add(name, load(files[i], fp), std::nullopt);
      }
      std::vector<LoadedMesh> loaded;
      for (std::size_t i = 0; i < files.size(); ++i) {
        loaded.push_back({files[i], &body.segments[i].mesh});
      }
      check_sizes(kp, loaded, lo.scale, folder);
    }
  }
  return body;
}

}  // namespace hapsim
