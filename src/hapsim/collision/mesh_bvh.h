// The exact proximity query: a bounding-volume hierarchy over a triangle mesh answering closest
// point, signed distance (angle-weighted pseudo-normals), triangle id and outward normal.
// It is the oracle every approximate method is checked against, and agrees with CGAL's
// AABB_tree to 1e-9 relative (tests/collision/mesh_bvh_oracle_test.cpp).
#pragma once

#include "hapsim/collision/proximity_query.h"
#include "hapsim/collision/signed_surface.h"
#include "hapsim/core/progress.h"
#include "hapsim/geometry/triangle_mesh.h"

#include <cstdint>
#include <vector>

namespace hapsim {

struct BvhBuildOptions {
  /// Largest number of triangles in a leaf.
  int max_leaf_triangles = 4;
  ProgressFn progress;
};

struct BvhStats {
  std::size_t nodes = 0;
  std::size_t leaves = 0;
  std::size_t depth = 0;
  double build_ms = 0.0;
  std::size_t memory_bytes = 0;
};

/// Work done by one query, for tests that assert algorithmic bounds (not timings).
struct QueryCounters {
  std::size_t nodes_visited = 0;
  std::size_t triangles_tested = 0;
};

class MeshBvh final : public ProximityQuery {
 public:
  /// Keeps a reference to `mesh`: it must outlive the BVH; after its vertices move, call refit().
  explicit MeshBvh(const TriangleMesh& mesh, BvhBuildOptions options = {});
  ~MeshBvh() override;

  [[nodiscard]] SurfacePoint closest_point(const Vec3& p, QueryHint* hint = nullptr) const override;
  bool contact_within(const Vec3& p, double radius, SurfacePoint* out,
                      QueryHint* hint = nullptr) const override;
  void refit() override;
  [[nodiscard]] std::size_t memory_bytes() const override;
  [[nodiscard]] std::string_view method_name() const override { return "exact"; }

  /// As closest_point, also counting the work done.
  [[nodiscard]] SurfacePoint closest_point_counted(const Vec3& p, QueryHint* hint,
                                                   QueryCounters* counters) const;
  /// As contact_within, also counting the work done.
  bool contact_within_counted(const Vec3& p, double radius, SurfacePoint* out, QueryHint* hint,
                              QueryCounters* counters) const;

  [[nodiscard]] const BvhStats& stats() const { return stats_; }
  [[nodiscard]] const TriangleMesh& mesh() const { return *mesh_; }
  [[nodiscard]] const SignedSurface& signed_surface() const { return sign_; }

 private:
  struct Impl;
  const TriangleMesh* mesh_;
  SignedSurface sign_;
  BvhStats stats_;
  Impl* impl_;  // owned; pimpl keeps node layout (SIMD) out of this header
};

}  // namespace hapsim
