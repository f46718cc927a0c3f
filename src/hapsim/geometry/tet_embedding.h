// A finer surface embedded in a tetrahedral mesh (SPEC §12): each surface vertex is tied to one
// tet by barycentric coordinates, so the picture (and contact) deforms with the volume. A vertex
// outside every tet (a surface a little proud of the tets) is tied to the nearest tet and its
// barycentric coordinates extrapolate (they may be negative), which moves it rigidly with that
// tet's affine motion.
#pragma once

#include "hapsim/core/types.h"
#include "hapsim/geometry/tet_mesh.h"

#include <array>
#include <cstdint>
#include <span>
#include <vector>

namespace hapsim {

struct TetEmbedding {
  std::uint32_t tet = 0;
  /// Weights of the tet's four nodes (sum 1; all ≥ 0 inside).
  std::array<double, 4> barycentric{};
  /// 0 inside the tet, else the distance to it at rest, metres.
  double distance_m = 0.0;
};

/// Embeds each point in `mesh` (rest positions). O(points · log tets): a uniform grid over the
/// tets finds the containing tet (of several, on a shared face, the one the point is deepest
/// in); a point outside every tet goes to the nearest boundary triangle's tet (a hierarchy of
/// boxes over the boundary). Tets that are out of range, non-finite or flat are never chosen. A
/// non-finite point gets tet 0, zero weights and an infinite distance. Throws hapsim::Error when
/// the mesh has no usable tet at all.
[[nodiscard]] std::vector<TetEmbedding> embed_points(const TetMesh& mesh,
                                                     std::span<const Vec3> points);

/// The embedded point's position for the tets' current node positions.
[[nodiscard]] inline Vec3 embedded_position(const TetMesh& mesh, std::span<const Vec3> nodes,
                                            const TetEmbedding& e) {
  const TetIndices& t = mesh.tets[e.tet];
  return e.barycentric[0] * nodes[t[0]] + e.barycentric[1] * nodes[t[1]] +
         e.barycentric[2] * nodes[t[2]] + e.barycentric[3] * nodes[t[3]];
}

}  // namespace hapsim
