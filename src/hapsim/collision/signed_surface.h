// Inside/outside for exact point queries on a triangle mesh, by angle-weighted pseudo-normals
// (Bærentzen & Aanæs, "Signed distance computation using the angle weighted pseudonormal",
// IEEE TVCG 2005): the sign of (p - c)·n, with n the pseudo-normal of the feature (face, edge or
// vertex) that holds the closest point c, is exact on closed, consistently oriented meshes.
// On open meshes (a sheet) it gives the side of the surface, which is what contact needs.
//
// Shared by the exact BVH and the sphere tree so both answer identically.
#pragma once

#include "hapsim/collision/point_triangle.h"
#include "hapsim/collision/surface_point.h"
#include "hapsim/geometry/triangle_mesh.h"

#include <cstddef>
#include <unordered_map>
#include <vector>

namespace hapsim {

class SignedSurface {
 public:
  SignedSurface() = default;
  /// Builds edge adjacency and vertex pseudo-normals: O(n) in triangles.
  explicit SignedSurface(const TriangleMesh& mesh);

  /// After vertices moved (same triangles): recompute pseudo-normals. O(n).
  void update_normals(const TriangleMesh& mesh);

  /// Completes a query: sign, outward normal and triangle id from one triangle's closest point.
  /// haptic path: no allocation.
  [[nodiscard]] SurfacePoint resolve(const TriangleMesh& mesh, const Vec3& p,
                                     std::uint32_t triangle, const TriangleClosest& closest) const;

  /// The neighbour of `triangle` across its edge k (0: ab, 1: bc, 2: ca); kNoTriangle on an open
  /// edge, kNonManifold where more than two triangles share the edge.
  [[nodiscard]] std::uint32_t neighbour(std::uint32_t triangle, int edge) const {
    return neighbours_[triangle][static_cast<std::size_t>(edge)];
  }
  [[nodiscard]] std::size_t open_edge_count() const { return open_edges_; }
  [[nodiscard]] std::size_t non_manifold_edge_count() const { return non_manifold_edges_.size(); }
  [[nodiscard]] std::size_t memory_bytes() const;

  static constexpr std::uint32_t kNonManifold = kNoTriangle - 1;

 private:
  [[nodiscard]] Vec3 edge_pseudo_normal(const TriangleMesh& mesh, std::uint32_t triangle,
                                        int edge) const;

  std::vector<TriangleIndices> neighbours_;
  std::vector<Vec3> vertex_pseudo_normals_;
  /// Sum of unit face normals around each non-manifold edge, keyed by triangle*3 + edge.
  std::unordered_map<std::uint64_t, Vec3> non_manifold_edges_;
  std::size_t open_edges_ = 0;
};

}  // namespace hapsim
