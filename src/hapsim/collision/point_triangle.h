// Exact closest point from a point to one triangle, with the feature (vertex, edge, face) it lies
// on, which selects the pseudo-normal that decides inside/outside (see signed_surface.h).
#pragma once

#include "hapsim/core/types.h"

namespace hapsim {

/// Which feature of triangle (a, b, c) holds the closest point.
enum class TriangleFeature : std::uint8_t {
  kVertexA,
  kVertexB,
  kVertexC,
  kEdgeAB,
  kEdgeBC,
  kEdgeCA,
  kFace,
};

struct TriangleClosest {
  Vec3 point;
  double distance_sq;
  TriangleFeature feature;
};

/// Closest point on triangle (a, b, c) to p (Ericson, Real-Time Collision Detection §5.1.5),
/// exact in double precision up to rounding; degenerate triangles reduce to edges/points.
TriangleClosest closest_point_on_triangle(const Vec3& p, const Vec3& a, const Vec3& b,
                                          const Vec3& c);

}  // namespace hapsim
