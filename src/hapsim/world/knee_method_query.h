// The query a mesh segment gets when its body asks for the knee method (Burdea et al. 1994;
// collision/knee_index.h). The knee method's planes stand in for the surface: an answer jumps
// where the point moves from one group's cone to the next, and is millimetres off where a
// segment is not star-shaped about its groups' centres. A penalty segment turns that into a
// force error, which the paper accepted; the god-object cannot: it keeps its proxy on the
// surface only with a continuous signed distance (on the real knee's patella the knee method
// lost the proxy 827 times in a 10 mm/s drag). So a proxy segment answers with the exact query,
// and a penalty segment keeps the knee method, its error against the exact query measured at
// load and said when it is large.
#pragma once

#include "hapsim/collision/knee_error.h"
#include "hapsim/collision/proximity_query.h"
#include "hapsim/geometry/triangle_mesh.h"
#include "hapsim/world/world_description.h"

#include <cstddef>
#include <memory>
#include <optional>
#include <string>
#include <utility>
#include <vector>

namespace hapsim {

/// The knee method's error on a segment is said when, on points within 5 mm of its rest surface,
/// the p95 distance error is above this, or it misses or invents more than kKneeRateLimit of
/// the contacts.
inline constexpr double kKneeErrorLimitM = 0.001;
inline constexpr double kKneeRateLimit = 0.01;

struct KneeMethodQuery {
  std::unique_ptr<ProximityQuery> query;
  /// The knee method's error against the exact query (penalty segments; empty for a proxy
  /// segment, which answers exactly).
  std::optional<ApproximationError> error;
  /// Whether that error is over kKneeErrorLimitM or kKneeRateLimit: to be said.
  bool poor = false;
};

/// A MeshBvh for a proxy segment; a KneeIndex for a penalty segment, measured against a MeshBvh
/// on 2000 points of the rest surface's ±5 mm band (deterministic). `mesh` must outlive the
/// query.
[[nodiscard]] KneeMethodQuery make_knee_method_query(const TriangleMesh& mesh,
                                                     ContactResponse response);

/// One sentence for a body whose penalty segments the knee method answers poorly: how many, and
/// the worst three by p95 error with their figures. `poor` holds (segment name, error) pairs.
[[nodiscard]] std::string describe_poor_knee_segments(
    const std::string& body, std::size_t penalty_segments,
    std::vector<std::pair<std::string, ApproximationError>> poor);

}  // namespace hapsim
