#include "hapsim/collision/hausdorff.h"

#include "hapsim/collision/mesh_bvh.h"
#include "hapsim/core/error.h"

#include <algorithm>
#include <cmath>

namespace hapsim {

double mean_edge_length(const TriangleMesh& mesh) {
  if (mesh.empty()) {
    return 0.0;
  }
  double sum = 0.0;
  for (std::size_t t = 0; t < mesh.triangle_count(); ++t) {
    const auto c = mesh.corners(t);
    sum += (c[1] - c[0]).norm() + (c[2] - c[1]).norm() + (c[0] - c[2]).norm();
  }
  return sum / (3.0 * static_cast<double>(mesh.triangle_count()));
}

OneSidedHausdorff one_sided_hausdorff(const TriangleMesh& from, const TriangleMesh& to,
                                      double sample_spacing_m) {
  if (from.empty() || to.empty()) {
    throw Error("hausdorff", "both meshes need triangles");
  }
  if (!(sample_spacing_m > 0.0) || !std::isfinite(sample_spacing_m)) {
    throw Error("hausdorff", "the sample spacing must be positive and finite");
  }
  const MeshBvh query(to);
  QueryHint hint;
  OneSidedHausdorff out;
  double covering_m = 0.0;
  // Neighbouring triangles share their edge samples: cheap duplicates, kept for simplicity.
  constexpr int kMaxDivisions = 256;
  for (std::size_t t = 0; t < from.triangle_count(); ++t) {
    const auto c = from.corners(t);
    const double longest =
        std::max({(c[1] - c[0]).norm(), (c[2] - c[1]).norm(), (c[0] - c[2]).norm()});
    const int n =
        std::clamp(static_cast<int>(std::ceil(longest / sample_spacing_m)), 1, kMaxDivisions);
    // Sub-triangles are the triangle scaled by 1/n: any point is within longest/(n sqrt 3) of a
    // sub-triangle corner (a triangle's farthest point from its corners is at most that far).
    covering_m = std::max(covering_m, longest / (static_cast<double>(n) * std::sqrt(3.0)));
    for (int i = 0; i <= n; ++i) {
      for (int j = 0; i + j <= n; ++j) {
        const double u = static_cast<double>(i) / n;
        const double v = static_cast<double>(j) / n;
        const Vec3 p = c[0] + u * (c[1] - c[0]) + v * (c[2] - c[0]);
        const double d = std::abs(query.closest_point(p, &hint).signed_distance);
        ++out.samples;
        if (d > out.sampled_m) {
          out.sampled_m = d;
          out.worst_point = p;
        }
      }
    }
  }
  out.bound_m = out.sampled_m + covering_m;
  return out;
}

HausdorffDistance hausdorff_distance(const TriangleMesh& a, const TriangleMesh& b,
                                     double sample_spacing_m) {
  if (sample_spacing_m == 0.0) {
    const double ea = mean_edge_length(a);
    const double eb = mean_edge_length(b);
    // A third of the finer mesh's edge: the covering radius (the bound's slack) stays small.
    sample_spacing_m = std::min(ea > 0.0 ? ea : eb, eb > 0.0 ? eb : ea) / 3.0;
  }
  HausdorffDistance out;
  out.a_to_b = one_sided_hausdorff(a, b, sample_spacing_m);
  out.b_to_a = one_sided_hausdorff(b, a, sample_spacing_m);
  return out;
}

}  // namespace hapsim
