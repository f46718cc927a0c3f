// A FEM body's "fem" settings in a scene file (docs/scene-format.md, "FEM bodies"):
//   "fem": {"elasticity": "corotational", "integration": "backward_euler", "dt_s": 0.01,
//           "regions": [{"region": 0, "youngs_modulus_pa": 20000, "poisson_ratio": 0.45, ...}],
//           "fixed": {"below_z_m": 0.001, "nodes": [...], "attached_to": [{"body": "table"}]}}
// with the volume from the body's "tet_block" or "tet_mesh" geometry. Every error is a
// hapsim::Error at "<file>:<JSON pointer>".
#pragma once

#include "hapsim/deform/fem_body_description.h"
#include "hapsim/scene/json_reader.h"

#include <memory>
#include <string>

namespace hapsim {

/// Reads `j` (the body's "fem" object at `ptr`; null: every default) for the volume `tets`.
/// Checks every region of the mesh has a material and every node index exists.
[[nodiscard]] FemBodyDescription read_fem_settings(const JsonReader& r, const JsonReader::Json* j,
                                                   const std::string& ptr, const TetMesh& tets,
                                                   bool embedded_surface, std::string source);

}  // namespace hapsim
