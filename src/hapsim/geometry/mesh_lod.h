// Levels of detail for display (issue 13 item 2): coarser triangle lists of a mesh, built once
// when it is loaded (meshoptimizer's edge collapse, each level from the one before), chosen per
// frame by how large their error looks on screen (render/lod_selection.h). Display only: the
// haptic path keeps the full mesh. A level's triangles index the full mesh's own vertices (the
// simplifier only picks which survive), so a level needs no vertex buffer of its own and a
// deformed mesh's new positions move every level alike.
#pragma once

#include "hapsim/geometry/triangle_mesh.h"

#include <cstddef>
#include <span>
#include <vector>

namespace hapsim {

struct LodLevel {
  /// Triangles over the full mesh's vertices.
  std::vector<TriangleIndices> triangles;
  /// How far this level may stray from the full mesh, metres: three times the sum of
  /// meshoptimizer's error estimates for each simplification from the full mesh down to this level
  /// (Hausdorff distances obey the triangle inequality, so a sum bounds a chain; the estimate is
  /// not a bound: the exact distance reached 2.3× it, hence the factor).
  /// tests/geometry/mesh_lod_test.cpp checks it against the exact Hausdorff distance on every part
  /// of the default knee.
  double error_m = 0.0;
};

struct LodBuildOptions {
  /// A mesh with fewer triangles gets no coarser levels (its full mesh is cheap enough).
  std::size_t min_triangles = 256;
  /// Each level aims at this fraction of the triangles of the one before.
  double reduction = 0.5;
  /// No level reports an error above this fraction of the mesh's largest bounding-box side.
  double max_error_rel = 0.04;
  /// At most this many coarser levels; they stop early when the error limit stops a level
  /// from shedding at least a fifth of the one before's triangles, or at `min_triangles`/4.
  int max_levels = 8;
};

/// The coarser levels of `mesh`, finest first (the full mesh itself is level 0 and not listed);
/// empty for a small mesh. Open meshes keep their border vertices (no gaps open at a cut).
[[nodiscard]] std::vector<LodLevel> build_lod_levels(const TriangleMesh& mesh,
                                                     const LodBuildOptions& options = {});

/// The same triangles, each with its own winding, in an order that reuses recently shaded
/// vertices (meshoptimizer's vertex cache optimiser), for drawing the full mesh: a software
/// rasteriser shades a vertex once per batch it appears in. The levels above are already so
/// ordered. Precondition: every index is below `vertex_count`.
[[nodiscard]] std::vector<TriangleIndices> vertex_cache_order(
    std::span<const TriangleIndices> triangles, std::size_t vertex_count);

}  // namespace hapsim
