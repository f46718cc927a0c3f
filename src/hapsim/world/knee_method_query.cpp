#include "hapsim/world/knee_method_query.h"

#include "hapsim/collision/knee_index.h"
#include "hapsim/collision/mesh_bvh.h"

#include <algorithm>
#include <cstdio>

namespace hapsim {

KneeMethodQuery make_knee_method_query(const TriangleMesh& mesh, ContactResponse response) {
  KneeMethodQuery out;
  if (response == ContactResponse::kProxy) {
    out.query = std::make_unique<MeshBvh>(mesh);
    return out;
  }
  auto knee = std::make_unique<KneeIndex>(mesh);
  constexpr double kBandM = 0.005;
  const MeshBvh exact(mesh);
  const std::vector<Vec3> points = sample_surface_band(mesh, 2000, kBandM);
  const ApproximationError e = measure_approximation_error(*knee, exact, points, kBandM);
  out.poor = e.p95_abs_error_m > kKneeErrorLimitM || e.miss_rate > kKneeRateLimit ||
             e.false_contact_rate > kKneeRateLimit;
  out.error = e;
  out.query = std::move(knee);
  return out;
}

std::string describe_poor_knee_segments(
    const std::string& body, std::size_t penalty_segments,
    std::vector<std::pair<std::string, ApproximationError>> poor) {
  std::sort(poor.begin(), poor.end(), [](const auto& a, const auto& b) {
    return a.second.p95_abs_error_m > b.second.p95_abs_error_m;
  });
  char text[200];
  std::snprintf(text, sizeof text,
                "%zu of its %zu penalty segment(s) more than %.0f mm off the exact surface at "
                "p95, or missing or inventing over %.0f%% of contacts, on points within 5 mm",
                poor.size(), penalty_segments, kKneeErrorLimitM * 1e3, kKneeRateLimit * 100.0);
  std::string out =
      "body '" + body + "' (contact_method knee): the knee method answers " + text + " (worst: ";
  for (std::size_t i = 0; i < std::min<std::size_t>(3, poor.size()); ++i) {
    const ApproximationError& e = poor[i].second;
    std::snprintf(text, sizeof text,
                  "%.1f mm at p95, %.1f mm at worst, %.1f%% missed, %.1f%% invented",
                  e.p95_abs_error_m * 1e3, e.max_abs_error_m * 1e3, 100.0 * e.miss_rate,
                  100.0 * e.false_contact_rate);
    out += (i > 0 ? "; '" : "'") + poor[i].first + "' " + text;
  }
  out +=
      "): they are not star-shaped about their groups' centres, as the method assumes; "
      "\"contact_method\": \"exact\" answers them exactly";
  return out;
}

}  // namespace hapsim
