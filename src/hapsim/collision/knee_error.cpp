#include "hapsim/collision/knee_error.h"

#include "hapsim/core/statistics.h"

#include <algorithm>
#include <cmath>
#include <random>

namespace hapsim {

ApproximationError measure_approximation_error(const ProximityQuery& method,
                                               const ProximityQuery& reference,
                                               std::span<const Vec3> points,
                                               double band_outside_m) {
  ApproximationError err;
  std::vector<double> abs_errors;
  abs_errors.reserve(points.size());
  for (const Vec3& p : points) {
    const SurfacePoint ref = reference.closest_point(p);
    if (!ref.found() || ref.signed_distance > band_outside_m) {
      continue;
    }
    ++err.points;
    const SurfacePoint got = method.closest_point(p);
    const bool ref_contact = ref.signed_distance < 0.0;
    const bool got_contact = got.found() && got.signed_distance < 0.0;
    err.reference_contacts += ref_contact ? 1 : 0;
    err.misses += (ref_contact && !got_contact) ? 1 : 0;
    err.false_contacts += (!ref_contact && got_contact) ? 1 : 0;
    if (got.found()) {
      ++err.answered;
      abs_errors.push_back(std::abs(got.signed_distance - ref.signed_distance));
    }
  }
  if (!abs_errors.empty()) {
    double sum = 0.0;
    for (double e : abs_errors) {
      sum += e;
    }
    err.mean_abs_error_m = sum / static_cast<double>(abs_errors.size());
    err.max_abs_error_m = *std::max_element(abs_errors.begin(), abs_errors.end());
    err.p95_abs_error_m = nearest_rank_percentile(abs_errors, 0.95);
  }
  if (err.reference_contacts > 0) {
    err.miss_rate = static_cast<double>(err.misses) / static_cast<double>(err.reference_contacts);
  }
  const std::size_t clear = err.points - err.reference_contacts;
  if (clear > 0) {
    err.false_contact_rate = static_cast<double>(err.false_contacts) / static_cast<double>(clear);
  }
  return err;
}

std::vector<Vec3> sample_surface_band(const TriangleMesh& mesh, std::size_t count, double band_m,
                                      std::uint64_t seed) {
  std::vector<double> cumulative_area(mesh.triangle_count());
  double total = 0.0;
  for (std::size_t t = 0; t < mesh.triangle_count(); ++t) {
    total += 0.5 * mesh.face_normal_area2(t).norm();
    cumulative_area[t] = total;
  }
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  std::vector<Vec3> points;
  points.reserve(count);
  for (std::size_t i = 0; i < count && total > 0.0; ++i) {
    const double pick = unit(rng) * total;
    const auto t = static_cast<std::size_t>(
        std::lower_bound(cumulative_area.begin(), cumulative_area.end(), pick) -
        cumulative_area.begin());
    const auto [a, b, c] = mesh.corners(std::min(t, mesh.triangle_count() - 1));
    double s = unit(rng), r = unit(rng);
    if (s + r > 1.0) {
      s = 1.0 - s;
      r = 1.0 - r;
    }
    const Vec3 on_surface = a + s * (b - a) + r * (c - a);
    const double offset = (2.0 * unit(rng) - 1.0) * band_m;
    points.push_back(on_surface +
                     offset * mesh.face_normal(std::min(t, mesh.triangle_count() - 1)));
  }
  return points;
}

}  // namespace hapsim
