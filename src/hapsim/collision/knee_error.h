// The knee method's reported error: how far its answers are from a reference query (the exact
// MeshBvh) on given points near the surface, and how often it misses or invents a contact.
#pragma once

#include "hapsim/collision/proximity_query.h"
#include "hapsim/geometry/triangle_mesh.h"

#include <cstddef>
#include <cstdint>
#include <span>
#include <vector>

namespace hapsim {

struct ApproximationError {
  /// Points compared: those the reference puts inside or within `band_outside_m` outside.
  std::size_t points = 0;
  /// Of those, points the approximate method answered (found()).
  std::size_t answered = 0;
  std::size_t reference_contacts = 0;  // reference signed distance < 0
  /// |signed distance − reference| over answered points, metres.
  double mean_abs_error_m = 0.0;
  double p95_abs_error_m = 0.0;
  double max_abs_error_m = 0.0;
  /// Reference says contact, method does not (not answered counts as no contact).
  std::size_t misses = 0;
  /// Reference says clear, method says contact.
  std::size_t false_contacts = 0;
  /// misses / reference_contacts, false_contacts / (points − reference_contacts).
  double miss_rate = 0.0;
  double false_contact_rate = 0.0;
};

/// Compares `method` with `reference` on `points` (mesh frame). Points farther than
/// `band_outside_m` outside (by the reference) are skipped: the knee method answers only near
/// the body. Not a haptic-path function (allocates).
[[nodiscard]] ApproximationError measure_approximation_error(const ProximityQuery& method,
                                                             const ProximityQuery& reference,
                                                             std::span<const Vec3> points,
                                                             double band_outside_m);

/// Points at a uniformly random signed offset in [−band_m, band_m] along the face normal from
/// area-uniform random surface points; deterministic for a given seed.
[[nodiscard]] std::vector<Vec3> sample_surface_band(const TriangleMesh& mesh, std::size_t count,
                                                    double band_m, std::uint64_t seed = 1);

}  // namespace hapsim
