#include "hapsim/geometry/mesh_argument.h"

#include "hapsim/core/error.h"
#include "hapsim/geometry/mesh_io.h"
#include "hapsim/geometry/mesh_validation.h"
#include "hapsim/geometry/procedural.h"

#include <cmath>
#include <functional>
#include <string_view>

namespace hapsim {
namespace {

struct Builtin {
  const char* name;
  const char* description;
  std::function<TriangleMesh()> make;
};

const std::vector<Builtin>& builtins() {
  static const std::vector<Builtin> list = {
      {"bumpy-sphere",
       "closed bumpy sphere, radius 50 mm, ~13.5k triangles (the paper's knee size)",
       [] { return make_bumpy_sphere(13500); }},
      {"bumpy-sphere-100k", "closed bumpy sphere, ~100k triangles",
       [] { return make_bumpy_sphere(100000); }},
      {"box", "closed box 100 x 60 x 40 mm, 12 triangles",
       [] { return make_box(Vec3(0.05, 0.03, 0.02)); }},
      {"sheet16", "open 16x16-node sheet, 200 mm square (the seed's virtual sheet)",
       [] { return make_sheet(16, 0.2); }},
      {"sheet256", "open 256x256-node sheet, 200 mm square", [] { return make_sheet(256, 0.2); }},
  };
  return list;
}

}  // namespace

std::vector<std::pair<std::string, std::string>> builtin_meshes() {
  std::vector<std::pair<std::string, std::string>> out;
  for (const Builtin& b : builtins()) {
    out.emplace_back(b.name, b.description);
  }
  return out;
}

MeshArgument load_mesh_argument(const std::string& spec, double scale) {
  if (!(scale > 0.0) || !std::isfinite(scale)) {
    throw Error("--scale", "must be a positive finite number, got " + std::to_string(scale));
  }
  MeshArgument out;
  out.name = spec;
  out.scale = scale;
  constexpr std::string_view kPrefix = "builtin:";
  if (spec.rfind(kPrefix, 0) == 0) {
    const std::string name = spec.substr(kPrefix.size());
    for (const Builtin& b : builtins()) {
      if (name == b.name) {
        out.mesh = b.make();
        if (scale != 1.0) {
          out.mesh.scale(scale);
        }
        const MeshReport report = validate_mesh(out.mesh);
        out.validation = report.summary();
        out.validation_json = report.to_json();
        return out;
      }
    }
    std::string known;
    for (const Builtin& b : builtins()) {
      known += (known.empty() ? "" : ", ") + std::string("builtin:") + b.name;
    }
    throw Error(spec, "unknown built-in mesh; known: " + known);
  }
  // Files: welded, validated and repaired per the default policy (unusable geometry refused,
  // removable defects dropped, topology problems reported as warnings).
  MeshReport report;
  MeshLoadOptions options;
  options.scale = scale;
  out.mesh = load_mesh(spec, options, &report);
  out.validation = report.summary();
  for (const std::string& note : report.notes) {
    out.validation += "\n             " + note;
  }
  out.validation_json = report.to_json();
  return out;
}

}  // namespace hapsim
