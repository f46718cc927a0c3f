// Automatic construction of the knee method's vertex groups (Burdea et al., "knee palpation",
// AI in Medicine 1994, §3.1.1; architecture.md#contact): a body's surface is cut into segments (connected
// components), each segment's vertices into groups of adjacent vertices, and each group gets a
// centroid inside the body about which its surface patch is star-shaped, so that a vertex is
// well described by spherical coordinates (direction, radius) about that centroid.
//
// Groups come from k-means (k-means++ seeding, fixed seed: builds are reproducible) on vertex
// position plus a scaled normal, so that the two sides of a thin part do not share a group. A
// group whose patch is not star-shaped about any admissible centroid is split in two, repeatedly.
#pragma once

#include "hapsim/core/progress.h"
#include "hapsim/geometry/triangle_mesh.h"

#include <cstddef>
#include <cstdint>
#include <vector>

namespace hapsim {

struct KneeGroupOptions {
  /// Wanted number of owned vertices per group (k = vertices / target per segment).
  std::size_t target_vertices_per_group = 48;
  /// Lloyd iterations after k-means++ seeding (stops earlier when assignments settle).
  int kmeans_iterations = 12;
  /// Seed of the k-means++ seeding; the same seed gives the same groups.
  std::uint64_t seed = 0x6b6e6565;  // "knee"
  /// Weight of the unit normal against position in the k-means feature, as a multiple of the
  /// expected group radius: keeps opposite sides of thin parts apart.
  double normal_weight = 1.0;
  /// Groups smaller than this are not split further even if not star-shaped.
  std::size_t min_group_vertices = 4;
  /// Rounds of splitting non-star-shaped groups.
  int max_split_rounds = 10;
  ProgressFn progress;
};

/// One group: the vertices it owns, the one-ring "halo" around them (so that every triangle
/// touching an owned vertex has all three corners in the group's vertex set), its triangles and
/// the centroid everything is expressed about.
struct KneeGroup {
  Vec3 centroid_m = Vec3::Zero();
  std::uint32_t segment = 0;
  /// Vertices owned by this group; every mesh vertex is owned by exactly one group.
  std::vector<std::uint32_t> owned;
  /// One-ring neighbours of owned vertices owned by other groups.
  std::vector<std::uint32_t> halo;
  /// Triangles with at least one owned corner.
  std::vector<std::uint32_t> triangles;
  /// Every triangle faces away from the centroid ((tri centroid − c)·n > 0, see
  /// is_star_shaped_about) and every owned and halo vertex is seen from the centroid through the
  /// body's interior, with the centroid inside the body.
  bool star_shaped = false;
};

/// A segment: one connected component of the mesh (a bone, a muscle), with its bounding sphere.
struct KneeSegment {
  Vec3 centroid_m = Vec3::Zero();
  /// Distance from the centroid to the farthest vertex.
  double radius_m = 0.0;
  /// Groups [group_begin, group_end) belong to this segment.
  std::uint32_t group_begin = 0;
  std::uint32_t group_end = 0;
};

struct KneeGroupStats {
  std::size_t segments = 0;
  std::size_t groups = 0;
  std::size_t vertices_per_group_min = 0;
  double vertices_per_group_mean = 0.0;
  std::size_t vertices_per_group_max = 0;
  /// Groups not star-shaped about any admissible centroid right after k-means.
  std::size_t non_star_before_split = 0;
  /// ... and after splitting (too small to split further, or out of rounds).
  std::size_t non_star_after_split = 0;
  std::size_t splits = 0;
  /// Groups whose plain vertex mean lay outside the body (the centroid had to be pulled in).
  std::size_t centroids_pulled_inside = 0;
  /// Groups whose centroid could not be placed inside the body at all.
  std::size_t centroids_outside = 0;
  double build_ms = 0.0;
};

struct KneeGrouping {
  std::vector<KneeSegment> segments;
  /// Groups of a segment are contiguous (see KneeSegment::group_begin).
  std::vector<KneeGroup> groups;
  /// The owning group of each vertex.
  std::vector<std::uint32_t> vertex_group;
  KneeGroupStats stats;
};

/// Builds segments and groups for a closed, outward-oriented mesh. An empty mesh gives no
/// segments and no groups.
/// Cost: O(iterations · vertices · groups per segment) for k-means plus a few exact
/// inside/outside queries per group.
[[nodiscard]] KneeGrouping build_knee_groups(const TriangleMesh& mesh,
                                             const KneeGroupOptions& options = {});

/// True when every listed triangle faces away from `centroid_m`: (tri centroid − c)·n > 0.
[[nodiscard]] bool is_star_shaped_about(const TriangleMesh& mesh,
                                        const std::vector<std::uint32_t>& triangles,
                                        const Vec3& centroid_m);

}  // namespace hapsim
