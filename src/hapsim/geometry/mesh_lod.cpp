#include "hapsim/geometry/mesh_lod.h"

#include <meshoptimizer.h>

#include <algorithm>
#include <cmath>

namespace hapsim {

std::vector<LodLevel> build_lod_levels(const TriangleMesh& mesh, const LodBuildOptions& options) {
  std::vector<LodLevel> levels;
  if (mesh.triangle_count() < options.min_triangles || mesh.vertex_count() == 0) {
    return levels;
  }
  // Float positions about the bounds' centre (precision); meshoptimizer's errors are relative
  // to its scale of them.
  const Vec3 centre = mesh.bounds().center();
  std::vector<float> positions;
  positions.reserve(3 * mesh.vertex_count());
  for (const Vec3& v : mesh.vertices) {
    for (int k = 0; k < 3; ++k) {
      positions.push_back(static_cast<float>(v[k] - centre[k]));
    }
  }
  const auto scale_m = static_cast<double>(
      meshopt_simplifyScale(positions.data(), mesh.vertex_count(), 3 * sizeof(float)));
  std::vector<unsigned> indices;
  indices.reserve(3 * mesh.triangle_count());
  for (const TriangleIndices& t : mesh.triangles) {
    indices.insert(indices.end(), t.begin(), t.end());
  }
  // An open mesh (a cut surface, a sheet) keeps its border, or its coarse levels would pull
  // away from the cut and open gaps; a closed one has no border and loses nothing by it.
  const unsigned flags = meshopt_SimplifyLockBorder;
  // meshoptimizer's error is an estimate (its quadric metric), not a bound: the exact Hausdorff
  // distance came out up to 2.3× it on the default knee's parts. Three times it is what a level
  // reports.
  constexpr double kEstimateMargin = 3.0;
  const double max_error_rel = std::max(options.max_error_rel, 0.0) / kEstimateMargin;
  const std::size_t floor_triangles = std::max<std::size_t>(options.min_triangles / 4, 4);
  double error_rel_sum = 0.0;
  std::vector<unsigned> out(indices.size());
  for (int level = 0; level < options.max_levels; ++level) {
    const std::size_t triangles = indices.size() / 3;
    const auto target_triangles = std::max(
        floor_triangles,
        static_cast<std::size_t>(std::floor(options.reduction * static_cast<double>(triangles))));
    if (target_triangles >= triangles) {
      break;
    }
    // The error left for this step: the chain's sum stays within max_error_rel.
    const double budget_rel = max_error_rel - error_rel_sum;
    if (!(budget_rel > 0.0)) {
      break;
    }
    float step_error_rel = 0.0f;
    const std::size_t n =
        meshopt_simplify(out.data(), indices.data(), indices.size(), positions.data(),
                         mesh.vertex_count(), 3 * sizeof(float), 3 * target_triangles,
                         static_cast<float>(budget_rel), flags, &step_error_rel);
    if (n == 0 || 5 * n > 4 * indices.size()) {
      break;  // the error limit stopped it shedding a fifth: no level worth its buffer
    }
    error_rel_sum += static_cast<double>(step_error_rel);
    // Reordered for the post-transform vertex cache: fewer vertices shaded twice.
    indices.resize(n);
    meshopt_optimizeVertexCache(indices.data(), out.data(), n, mesh.vertex_count());
    LodLevel& l = levels.emplace_back();
    l.error_m = kEstimateMargin * error_rel_sum * scale_m;
    l.triangles.reserve(n / 3);
    for (std::size_t i = 0; i + 2 < n; i += 3) {
      l.triangles.push_back({indices[i], indices[i + 1], indices[i + 2]});
    }
  }
  return levels;
}

std::vector<TriangleIndices> vertex_cache_order(std::span<const TriangleIndices> triangles,
                                                std::size_t vertex_count) {
  static_assert(sizeof(TriangleIndices) == 3 * sizeof(unsigned), "triangles are 3 indices");
  std::vector<TriangleIndices> out(triangles.size());
  // meshoptimizer reads and writes flat index lists; a triangle's three stay in their order.
  meshopt_optimizeVertexCache(reinterpret_cast<unsigned*>(out.data()),
                              reinterpret_cast<const unsigned*>(triangles.data()),
                              3 * triangles.size(), vertex_count);
  return out;
}

}  // namespace hapsim
