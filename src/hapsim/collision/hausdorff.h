// Hausdorff distance between two triangle surfaces with the exact closest-point query (MeshBvh):
// how far a simplified mesh strays from its source, both ways. Each surface is sampled on a
// barycentric grid per triangle (spacing at most `sample_spacing_m`) and every sample is queried
// against the other surface. The distance to a surface is 1-Lipschitz, and every point of a
// triangle lies within (longest sub-triangle edge)/sqrt(3) of a grid sample, so the largest
// sampled distance plus that covering radius is an upper bound of the true one-sided Hausdorff
// distance; the sampled value itself is a lower bound.
#pragma once

#include "hapsim/core/types.h"
#include "hapsim/geometry/triangle_mesh.h"

#include <algorithm>
#include <cstddef>

namespace hapsim {

struct OneSidedHausdorff {
  double sampled_m = 0.0;           ///< largest distance found at a sample (lower bound)
  double bound_m = 0.0;             ///< sampled_m + the samples' covering radius (upper bound)
  Vec3 worst_point = Vec3::Zero();  ///< the sample at sampled_m
  std::size_t samples = 0;
};

struct HausdorffDistance {
  OneSidedHausdorff a_to_b;  ///< points of surface a against surface b
  OneSidedHausdorff b_to_a;
  [[nodiscard]] double sampled_m() const { return std::max(a_to_b.sampled_m, b_to_a.sampled_m); }
  [[nodiscard]] double bound_m() const { return std::max(a_to_b.bound_m, b_to_a.bound_m); }
};

/// The largest distance from the points of `from` to the surface `to` (sampled as above).
/// Throws hapsim::Error("hausdorff", …) when either mesh has no triangles or the spacing is not
/// positive and finite.
[[nodiscard]] OneSidedHausdorff one_sided_hausdorff(const TriangleMesh& from,
                                                    const TriangleMesh& to,
                                                    double sample_spacing_m);

/// Both directions. A spacing of 0 takes a third of the finer mesh's mean edge length.
[[nodiscard]] HausdorffDistance hausdorff_distance(const TriangleMesh& a, const TriangleMesh& b,
                                                   double sample_spacing_m = 0.0);

/// Mean edge length over all triangles' edges (0 for an empty mesh).
[[nodiscard]] double mean_edge_length(const TriangleMesh& mesh);

}  // namespace hapsim
