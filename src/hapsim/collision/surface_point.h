// The answer of every proximity query (exact BVH, sphere tree, knee method): the closest point
// on a body's surface to a query point, with inside/outside sign and outward normal.
#pragma once

#include "hapsim/core/types.h"

namespace hapsim {

/// SurfacePoint::triangle of an answer from a signed distance field rather than a mesh triangle.
inline constexpr std::uint32_t kSdfSurface = kNoTriangle - 1;

struct SurfacePoint {
  /// Closest point on the surface, in the mesh's frame (metres).
  Vec3 point = Vec3::Zero();
  /// Outward unit normal: (p - point)/|p - point| turned outward, or the surface pseudo-normal
  /// when the query point lies on the surface.
  Vec3 normal = Vec3::Zero();
  /// Distance to the surface, negative inside the body (metres).
  double signed_distance = kInf;
  /// Index of the triangle that holds `point`; kNoTriangle if the query found nothing;
  /// kSdfSurface when a signed distance field answered (CsgQuery): found, but no triangle.
  std::uint32_t triangle = kNoTriangle;

  [[nodiscard]] bool found() const { return triangle != kNoTriangle; }
  [[nodiscard]] bool inside() const { return signed_distance < 0.0; }
};

/// Temporal coherence: the triangle that answered last cycle. A haptic probe moves a fraction of
/// a millimetre per millisecond, so last cycle's triangle bounds this cycle's distance tightly.
struct QueryHint {
  std::uint32_t triangle = kNoTriangle;
};

}  // namespace hapsim
