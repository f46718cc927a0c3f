// Polygoniser: turns any CSG tree (any signed distance field with conservative bounds) into a
// closed triangle mesh for display and for building contact trees.
//
// Method: marching tetrahedra on a regular grid, each cube split into the 6 Kuhn tetrahedra
// around its main diagonal (the same split in every cube, so faces match and the result is
// watertight without a case table for cubes). Vertices live on grid edges and are shared by edge
// key; each vertex is then moved *along its own grid edge* to the zero crossing (safeguarded
// Newton / bisection), so it lies on the surface to ~1e-9 of the solid's size. Keeping vertices
// strictly inside their edges means no triangle can fold or flip, whatever the field does.
//
// Output guarantees: closed (every edge shared by exactly two triangles, used once in each
// direction), manifold by vertex index, outward-oriented (positive signed volume). Grid nodes
// with distance exactly 0 count as outside; then a vertex can coincide with a grid node and
// triangles may be degenerate (zero area) — they are kept because removing them would open the
// mesh; `PolygonizeStats::degenerate_triangles` counts them.
// Limits: features thinner than a cell may vanish or break apart; sharp CSG edges and corners
// are bevelled at about the cell size (vertices are on the surface, triangles cut corners).
#pragma once

#include "hapsim/core/progress.h"
#include "hapsim/geometry/csg.h"
#include "hapsim/geometry/triangle_mesh.h"

#include <array>
#include <cstddef>
#include <functional>

namespace hapsim {

struct PolygonizeOptions {
  /// Grid cell edge length, metres. Set this or `max_cells_per_axis` (or both: the coarser of
  /// the two wins, so `max_cells_per_axis` caps the resolution).
  double cell_size_m = 0.0;
  /// Upper bound on the number of cells along the longest side of the solid's bounds.
  int max_cells_per_axis = 0;
  /// Empty cells added around the solid's bounds on each side (≥ 1), so the surface never
  /// touches the grid border.
  int padding_cells = 2;
  /// Move each vertex along its grid edge onto the zero set (recommended); false keeps the
  /// linear interpolation of the two node distances.
  bool refine_vertices = true;
  /// Fill `vertex_normals` with the SDF gradient at each vertex (sharp shading at CSG edges);
  /// false leaves them empty (call TriangleMesh::compute_vertex_normals()).
  bool gradient_normals = true;
  /// Refuse grids with more nodes than this (memory and time guard): hapsim::Error instead.
  std::size_t max_grid_nodes = 64'000'000;
  /// Threads for evaluating the grid (0: hardware concurrency). The mesh does not depend on it.
  int threads = 0;
  /// Progress ("polygonize", fraction of grid slabs done). May be empty.
  ProgressFn progress;
};

/// What the polygoniser did, for logs and tests.
struct PolygonizeStats {
  double cell_size_m = 0.0;
  /// Grid nodes along x, y, z.
  std::array<int, 3> grid_nodes{0, 0, 0};
  /// Signed distance evaluations (grid nodes plus vertex refinement).
  std::size_t sdf_evaluations = 0;
  /// Triangles with (numerically) zero area, kept to keep the mesh closed.
  std::size_t degenerate_triangles = 0;
  /// Largest |distance| at an output vertex, metres.
  double max_vertex_distance_m = 0.0;
};

/// Any signed distance field (negative inside, the right sign everywhere, |value| at most the
/// true distance), e.g. an offset of meshes' exact signed distances built in a higher layer.
struct DistanceField {
  /// Distance and unit outward gradient; called from several threads at once.
  std::function<SdfSample(const Vec3&)> evaluate;
  /// Distance only (same value as evaluate), for the grid; called from several threads at once.
  std::function<double(const Vec3&)> distance;
  /// A box containing everything inside the field.
  Box3 bounds;
};

/// Polygonises a distance field, as the CSG overload below (which wraps its solid in one).
TriangleMesh polygonize(const DistanceField& field, const PolygonizeOptions& options,
                        PolygonizeStats* stats = nullptr);

/// Polygonises `solid`. Throws hapsim::Error (where = "polygonize") for: no cell size or
/// resolution, non-positive/non-finite cell size, an empty solid (structurally, or no grid node
/// inside it, e.g. sphere(1) − sphere(2), or thinner than a cell everywhere), unbounded
/// bounds, or a grid above `max_grid_nodes`. Deterministic for given inputs.
TriangleMesh polygonize(const CsgSolid& solid, const PolygonizeOptions& options,
                        PolygonizeStats* stats = nullptr);

}  // namespace hapsim
