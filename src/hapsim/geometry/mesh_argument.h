// A mesh named the way a user names one (the CLI's MESH arguments, the Python module's
// load_mesh): a file (through geometry/mesh_io) or a built-in mesh (`builtin:NAME`), scaled to
// metres.
#pragma once

#include "hapsim/geometry/triangle_mesh.h"

#include <string>
#include <vector>

namespace hapsim {

struct MeshArgument {
  TriangleMesh mesh;       // metres
  std::string name;        // as given on the command line
  double scale = 1.0;      // file units -> metres
  std::string validation;  // human summary of the validation report
  std::string validation_json;
};

/// Built-in meshes: name and one-line description.
std::vector<std::pair<std::string, std::string>> builtin_meshes();

/// Loads `spec` ("builtin:NAME" or a path) scaled by `scale`. Throws hapsim::Error naming the
/// file (or the unknown built-in, listing the known ones).
MeshArgument load_mesh_argument(const std::string& spec, double scale);

}  // namespace hapsim
