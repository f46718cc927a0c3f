// Shading of machined shapes: a mesh with a vertex per triangle corner whose normal averages only
// the faces around it within a crease angle of its own face, so a CAD part's flat faces and sharp
// edges stay flat and sharp while its curved surfaces stay smooth (welded normals round every
// edge off; a normal per face shows every facet of a curve).
#pragma once

#include "hapsim/geometry/triangle_mesh.h"

namespace hapsim {

/// `crease_rad` 0 gives face normals (a box with flat faces); about 0.6 suits CAD meshes.
[[nodiscard]] TriangleMesh with_creased_normals(const TriangleMesh& mesh, double crease_rad);

}  // namespace hapsim
