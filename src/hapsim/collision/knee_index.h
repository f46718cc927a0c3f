// The knee method (Burdea et al. 1994, §3.1.1; architecture.md#contact) as a selectable
// ProximityQuery:
//   segment bounding sphere → groups whose sphere of influence holds the point, deepest first →
//   the group's vertices in spherical coordinates about its centroid → the three vertices
//   closest in angle to the point → the plane through them → if the point is on the centroid's
//   side, contact with penetration = distance to that plane; otherwise the next group.
//
// It is approximate (the plane through three nearby vertices stands in for the surface) and it
// answers only near the body: a point outside every sphere of influence (grown by
// `influence_margin_m`) gets found() == false and signed_distance == +inf. Its error against the
// exact query is measured by knee_error.h. A point near the surface whose direction falls in no
// candidate group's cone (a gap between the cones of neighbouring centroids) gets the plane of
// the group whose cone it misses by the least. An index of an empty mesh never answers.
//
// Deformation model (the paper's): vertices move along their group's radial direction, so the
// stored directions stay those of the rest shape and refit() only updates radii and bounds.
#pragma once

#include "hapsim/collision/knee_groups.h"
#include "hapsim/collision/proximity_query.h"
#include "hapsim/geometry/triangle_mesh.h"

#include <array>
#include <cstdint>
#include <span>
#include <vector>

namespace hapsim {

/// Which three vertices give the plane.
enum class KneeTripleRule : std::uint8_t {
  /// The paper's: the three vertices closest in angle (degenerate triples are replaced by the
  /// next-closest vertex). Poor on anisotropic meshes, where the closest three lie on one line.
  kClosestThree,
  /// Among the four closest in angle, the first non-degenerate triple whose cone about the
  /// centroid contains the point's direction.
  kEnclosingOfFour,
  /// The mesh triangle, in the vertex fans of the four closest in angle, whose cone contains the
  /// point's direction: the plane of the triangle the centroid's ray actually crosses. Falls
  /// back to kEnclosingOfFour.
  kEnclosingTriangle,
};

/// What one query looked at (the knee paper's Fig. 3, for display and tests): the group that
/// answered and the three vertices closest in angle to the point about that group's centroid.
struct KneeQueryTrace {
  static constexpr std::uint32_t kNoGroup = ~std::uint32_t{0};
  /// The group whose plane gave the answer; kNoGroup when the query found nothing.
  std::uint32_t group = kNoGroup;
  /// Mesh vertex ids (the group's owned and halo vertices), closest in angle first.
  std::array<std::uint32_t, 3> closest_vertices{};
  /// How many of closest_vertices are set: 3, fewer only for a group of fewer vertices.
  std::size_t vertex_count = 0;
};

struct KneeIndexOptions {
  KneeGroupOptions groups;
  /// Spheres of influence are grown by this much for closest_point(), so that points just
  /// outside the surface still get a (positive) distance. contact_within(p, r) grows them by r.
  double influence_margin_m = 0.003;
  KneeTripleRule triple_rule = KneeTripleRule::kEnclosingTriangle;
};

struct KneeIndexStats {
  KneeGroupStats groups;
  /// Group vertex entries (owned + halo) over owned vertices: the cost of overlapping groups.
  double entries_per_vertex = 0.0;
  std::size_t memory_bytes = 0;
  double build_ms = 0.0;
};

/// Work done by one query, for tests that assert algorithmic bounds (not timings).
struct KneeCounters {
  std::size_t segments_tested = 0;
  /// Group spheres of influence tested against the point.
  std::size_t group_spheres_tested = 0;
  /// Groups whose vertices were scanned for the three closest in angle.
  std::size_t groups_visited = 0;
  std::size_t vertices_scanned = 0;
};

class KneeIndex final : public ProximityQuery {
 public:
  /// Keeps a reference to `mesh` (closed, outward-oriented): it must outlive the index; after
  /// its vertices move, call refit() or refit_vertices().
  explicit KneeIndex(const TriangleMesh& mesh, KneeIndexOptions options = {});

  /// Approximate closest surface point: the projection of `p` on the plane of the three
  /// vertices closest in angle; normal = that plane's outward normal; triangle = one incident to
  /// the nearest of the three. `hint` is only written (the answer's triangle).
  [[nodiscard]] SurfacePoint closest_point(const Vec3& p, QueryHint* hint = nullptr) const override;
  bool contact_within(const Vec3& p, double radius, SurfacePoint* out,
                      QueryHint* hint = nullptr) const override;
  /// Full refit from the mesh: radii of every vertex entry, group and segment sphere radii. O(n).
  void refit() override;
  [[nodiscard]] std::size_t memory_bytes() const override;
  [[nodiscard]] std::string_view method_name() const override { return "knee"; }

  /// Local refit after only `moved` vertices changed: O(entries of those vertices). Sphere radii
  /// only grow here (a bound that stays valid); refit() tightens them again. haptic path.
  void refit_vertices(std::span<const std::uint32_t> moved);

  /// As closest_point, also counting the work done.
  [[nodiscard]] SurfacePoint closest_point_counted(const Vec3& p, KneeCounters* counters) const;

  /// The group closest_point(p) answers from and its three vertices closest in angle to p.
  /// Not for the haptic path (a second scan of the group).
  [[nodiscard]] KneeQueryTrace trace(const Vec3& p) const;

  /// The group that owns vertex `v`, and its unit radial direction about that group's centroid
  /// at rest: the direction the deformation model moves it along.
  [[nodiscard]] std::uint32_t vertex_group(std::uint32_t v) const { return vertex_group_[v]; }
  [[nodiscard]] const Vec3& radial_direction(std::uint32_t v) const { return radial_dir_[v]; }
  [[nodiscard]] std::size_t group_count() const { return groups_.size(); }
  [[nodiscard]] const Vec3& group_centroid(std::uint32_t g) const { return groups_[g].centroid_m; }
  /// Radius of group g's sphere of influence (farthest vertex of its owned + halo set).
  [[nodiscard]] double group_radius(std::uint32_t g) const { return groups_[g].radius_m; }
  /// Owned vertex ids of group g.
  [[nodiscard]] std::span<const std::uint32_t> group_vertices(std::uint32_t g) const;

  /// A priori bound on |signed distance error| for points within `band_m` of the surface, from
  /// the mesh: max over groups of (longest edge)·(sine of the largest normal deviation between
  /// triangles of the group) plus a curvature term; see knee_index.cpp for the derivation.
  [[nodiscard]] double error_bound_m(double band_m) const;

  [[nodiscard]] const KneeIndexStats& stats() const { return stats_; }
  [[nodiscard]] const TriangleMesh& mesh() const { return *mesh_; }

 private:
  struct Segment {
    Vec3 centroid_m;
    double radius_m;
    std::uint32_t group_begin, group_end;
  };
  struct Group {
    Vec3 centroid_m;
    double radius_m;  // sphere of influence: farthest entry
    std::uint32_t segment;
    std::uint32_t entry_begin, entry_owned_end, entry_end;
    Vec3 cone_axis;     // mean rest direction of the entries
    double cone_cos;    // min over entries of axis·u: directions outside this cone miss the patch
    double max_edge_m;  // longest edge of the group's triangles
    double normal_spread_rad;  // largest angle between normals of triangles sharing a vertex
  };

  /// `answered_group`, when given, gets the group whose plane answered (kNoGroup: none).
  SurfacePoint query(const Vec3& p, double margin_m, KneeCounters* counters,
                     std::uint32_t* answered_group = nullptr) const;
  /// Plane test of one group. Returns false when the point's direction from the centroid is
  /// outside the group's cone (nothing computed); otherwise fills `answer`, and `covers` tells
  /// whether the direction falls in the group's own patch (owned nearest vertex, enclosing
  /// triple). `use_cone` false skips the cone test (the last resort of query()).
  bool plane_for_group(const Vec3& p, std::uint32_t g, KneeCounters* counters, SurfacePoint* answer,
                       bool* covers, bool use_cone = true) const;
  void refit_bounds_tight();

  const TriangleMesh* mesh_;
  KneeIndexOptions options_;
  std::vector<Segment> segments_;
  std::vector<Group> groups_;
  // Group vertex entries (owned first, then halo), SoA so the angular scan vectorises: rest unit
  // direction about the group centroid (float: only compared), current radius, vertex id. The
  // plane itself uses the mesh's current vertex positions.
  std::vector<float> ux_, uy_, uz_;
  std::vector<double> r_;
  std::vector<std::uint32_t> entry_vertex_;
  // Per vertex: owning group, rest radial direction, one incident triangle, entries (CSR).
  std::vector<std::uint32_t> vertex_group_;
  std::vector<Vec3> radial_dir_;
  std::vector<std::uint32_t> vertex_triangle_;
  std::vector<std::uint32_t> vertex_fan_begin_, vertex_fan_;  // vertex → incident triangles
  std::vector<std::uint32_t> vertex_entry_begin_, vertex_entries_;
  std::vector<std::uint32_t> owned_vertices_;  // group_vertices() storage
  std::vector<std::uint32_t> owned_begin_;
  KneeIndexStats stats_;
};

}  // namespace hapsim
