// Sphere trees (seed 000 §3.1): a hierarchy of bounding spheres over a mesh's surface. Children
// of a level-i sphere are level-(i+1) spheres that it bounds; leaves hold a few triangles.
// Point/sphere queries use the spheres to find candidates, then refine with exact triangle tests,
// so they return the same closest point as MeshBvh. Tree-vs-tree descends only where parent
// spheres overlap (the ball vs the sheet, a fingertip vs a bone). After vertices move, refit()
// recomputes the spheres bottom-up without rebuilding the hierarchy.
#pragma once

#include "hapsim/collision/proximity_query.h"
#include "hapsim/collision/signed_surface.h"
#include "hapsim/core/progress.h"
#include "hapsim/geometry/triangle_mesh.h"

#include <cstdint>
#include <span>
#include <vector>

namespace hapsim {

struct Sphere {
  Vec3 center = Vec3::Zero();
  double radius = 0.0;
};

struct SphereTreeOptions {
  /// Children per inner node.
  int branching = 4;
  /// Largest number of triangles in a leaf.
  int max_leaf_triangles = 4;
  ProgressFn progress;
};

struct SphereTreeStats {
  std::size_t nodes = 0;
  std::size_t leaves = 0;
  /// Number of levels (a tree that is a single leaf has depth 1).
  std::size_t depth = 0;
  double build_ms = 0.0;
  std::size_t memory_bytes = 0;
  /// Mean over leaves of (leaf sphere radius / radius of the minimal enclosing sphere of the
  /// leaf's triangles); 1.0 is perfectly tight.
  double leaf_tightness = 0.0;
  /// Same ratio over inner nodes against the minimal sphere of all triangles below them.
  double inner_tightness = 0.0;
};

/// Overlapping leaves of two trees: leaf indices into each tree's leaf list.
struct LeafPair {
  std::uint32_t leaf_a;
  std::uint32_t leaf_b;
};

struct TreeTraversalCounters {
  std::size_t sphere_tests = 0;
};

/// Work done by one point query, for tests that assert algorithmic behaviour (not timings).
struct SphereQueryCounters {
  std::size_t nodes_visited = 0;
  std::size_t sphere_tests = 0;
  std::size_t triangles_tested = 0;
};

class SphereTree final : public ProximityQuery {
 public:
  /// Keeps a reference to `mesh`: it must outlive the tree; after its vertices move, call refit().
  explicit SphereTree(const TriangleMesh& mesh, SphereTreeOptions options = {});
  ~SphereTree() override;

  [[nodiscard]] SurfacePoint closest_point(const Vec3& p, QueryHint* hint = nullptr) const override;
  bool contact_within(const Vec3& p, double radius, SurfacePoint* out,
                      QueryHint* hint = nullptr) const override;
  void refit() override;
  [[nodiscard]] std::size_t memory_bytes() const override;
  [[nodiscard]] std::string_view method_name() const override { return "spheretree"; }

  /// As closest_point / contact_within, also counting the work done (adds to `counters`).
  [[nodiscard]] SurfacePoint closest_point_counted(const Vec3& p, QueryHint* hint,
                                                   SphereQueryCounters* counters) const;
  bool contact_within_counted(const Vec3& p, double radius, SurfacePoint* out, QueryHint* hint,
                              SphereQueryCounters* counters) const;

  /// Pairs of leaves whose spheres overlap, with `other` placed by X_this_other (other's frame
  /// into this tree's frame). Descends only where parent spheres overlap. Spheres less than
  /// `margin_m` apart count as overlapping, so every point of either surface within margin_m of
  /// the other surface lies in a returned pair's leaves. Appends to `out` (reserve it to stay
  /// allocation-free on the haptic path) until it holds `max_pairs`; returns false when it stopped
  /// there with pairs left unvisited.
  bool overlapping_leaves(const SphereTree& other, const Iso3& X_this_other,
                          std::vector<LeafPair>& out, TreeTraversalCounters* counters = nullptr,
                          double margin_m = 0.0,
                          std::size_t max_pairs = static_cast<std::size_t>(-1)) const;

  // Structure access (viewer's sphere display, tests of invariants).
  [[nodiscard]] std::size_t node_count() const;
  [[nodiscard]] Sphere node_sphere(std::size_t node) const;
  [[nodiscard]] std::size_t node_level(std::size_t node) const;  // root = 0
  [[nodiscard]] std::span<const std::uint32_t> node_children(std::size_t node) const;
  [[nodiscard]] std::size_t leaf_count() const;
  [[nodiscard]] std::size_t leaf_node(std::size_t leaf) const;  // node index of a leaf
  [[nodiscard]] std::span<const std::uint32_t> leaf_triangles(std::size_t leaf) const;

  [[nodiscard]] const SphereTreeStats& stats() const { return stats_; }
  /// Recomputes stats().leaf_tightness / inner_tightness against the minimal spheres of the
  /// triangles below each node: O(n log n). The constructor calls it; refit() does not.
  void update_tightness();
  [[nodiscard]] const TriangleMesh& mesh() const { return *mesh_; }
  [[nodiscard]] const SignedSurface& signed_surface() const { return sign_; }

 private:
  struct Impl;
  const TriangleMesh* mesh_;
  SignedSurface sign_;
  SphereTreeStats stats_;
  Impl* impl_;  // owned
};

}  // namespace hapsim
