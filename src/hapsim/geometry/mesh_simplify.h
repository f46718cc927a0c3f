// Mesh simplification to a vertex budget (meshoptimizer's edge-collapse simplifier), keeping a
// closed surface closed: the knee paper's model is ~13.5k vertices over all parts, the real
// anatomy it is derived from ~20x that. The simplifier only removes vertices (the survivors keep
// their exact positions), so the error it causes lives inside the new, larger triangles:
// measure it with hausdorff_distance (collision/hausdorff.h).
#pragma once

#include "hapsim/geometry/triangle_mesh.h"

#include <cstddef>
#include <string>

namespace hapsim {

struct MeshSimplifyOptions {
  /// Largest number of vertices the result may have (> 0).
  std::size_t target_vertices = 0;
  /// Attempts at a smaller index budget when a result is over the vertex budget or not a valid
  /// closed surface (a collapse can pinch a thin part into a non-manifold edge).
  int max_attempts = 40;
};

struct MeshSimplifyResult {
  TriangleMesh mesh;
  std::size_t source_vertices = 0;
  std::size_t source_triangles = 0;
  /// meshoptimizer's own error estimate (its quadric metric), metres; not a distance bound.
  double simplifier_error_m = 0.0;
  int attempts = 0;
  /// Folded edges of the simplifier's result flipped away (mesh_unfold.h) in the last attempt.
  std::size_t unfolded_edges = 0;
  /// Whether the result is closed, free of defects and of folds the source has not (always true
  /// when the source was, unless no attempt reached one; `problem` then says why).
  bool valid = false;
  std::string problem;
};

/// Simplifies `source` (welded: simplification needs shared vertices) to at most
/// `options.target_vertices` vertices. A source already within budget is returned unchanged.
/// Throws hapsim::Error("simplify", …) when the budget is 0 or the source has no triangles.
[[nodiscard]] MeshSimplifyResult simplify_mesh(const TriangleMesh& source,
                                               const MeshSimplifyOptions& options);

/// Collapses the shortest edge of every (near-)zero-area triangle (twice its area at most 1e-8
/// of the squared bounds diagonal) and drops the triangles that lose a corner, repeating while a
/// collapse leaves a new one; keeps a closed mesh closed where dropping them would open it.
/// Returns the number of edges collapsed.
std::size_t collapse_degenerate_triangles(TriangleMesh& mesh);

}  // namespace hapsim
