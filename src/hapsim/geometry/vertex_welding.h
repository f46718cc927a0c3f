// Vertex welding: merging vertices that share a position, so triangle soup (STL stores three
// private corners per triangle) becomes an indexed, connected surface that validation and
// contact queries can reason about (open edges, orientation, inside/outside).
#pragma once

#include "hapsim/geometry/triangle_mesh.h"

#include <cstddef>

namespace hapsim {

/// Merges vertices closer than `tolerance_m` (0 or less: exact duplicates only; −0 equals +0;
/// non-finite vertices merge only with bit-identical ones, so a NaN vertex the importer
/// repeated per face corner is counted once), renumbers triangles, drops the merged vertices and
/// returns how many were removed. Greedy on a hash grid: a vertex joins the first earlier
/// representative within the tolerance, so chains are not merged transitively. Triangles whose
/// indices are out of range are left as they are (still out of range). Vertex normals are
/// recomputed if present. Welding can make small triangles degenerate (repeated index):
/// validate afterwards.
std::size_t weld_vertices(TriangleMesh& mesh, double tolerance_m = 0.0);

}  // namespace hapsim
