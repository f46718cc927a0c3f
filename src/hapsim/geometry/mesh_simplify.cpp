#include "hapsim/geometry/mesh_simplify.h"

#include "hapsim/core/error.h"
#include "hapsim/geometry/mesh_unfold.h"
#include "hapsim/geometry/mesh_validation.h"

#include <meshoptimizer.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <map>
#include <vector>

namespace hapsim {
namespace {

// One meshoptimizer pass at an index budget. Positions go to float relative to the bounds'
// centre (precision), but the result keeps the source's double vertices: the simplifier only
// picks which vertices survive.
TriangleMesh simplify_once(const TriangleMesh& source, const std::vector<float>& positions,
                           const std::vector<unsigned>& indices, std::size_t target_indices,
                           double extent_m, double* error_m) {
  std::vector<unsigned> out(indices.size());
  float error_rel = 0.0f;
  // target_error 1 (relative to the mesh extent): no error limit, the budget decides.
  const std::size_t n = meshopt_simplify(out.data(), indices.data(), indices.size(),
                                         positions.data(), source.vertex_count(), 3 * sizeof(float),
                                         target_indices, 1.0f, 0, &error_rel);
  *error_m = static_cast<double>(error_rel) * extent_m;
  TriangleMesh mesh;
  mesh.vertices = source.vertices;
  mesh.triangles.reserve(n / 3);
  for (std::size_t i = 0; i + 2 < n; i += 3) {
    mesh.triangles.push_back({out[i], out[i + 1], out[i + 2]});
  }
  mesh.remove_unused_vertices();
  return mesh;
}

std::size_t collapse_once(TriangleMesh& mesh) {
  // Well above validation's 1e-12, so a sliver stays non-degenerate when written as float32.
  const double area2_limit = 1e-8 * mesh.bounds().diagonal().squaredNorm();
  std::vector<std::uint32_t> to(mesh.vertex_count());
  for (std::uint32_t i = 0; i < to.size(); ++i) {
    to[i] = i;
  }
  const auto find = [&](std::uint32_t v) {
    while (to[v] != v) {
      v = to[v];
    }
    return v;
  };
  std::size_t collapsed = 0;
  for (std::size_t t = 0; t < mesh.triangle_count(); ++t) {
    if (mesh.face_normal_area2(t).norm() > area2_limit) {
      continue;
    }
    const TriangleIndices& tri = mesh.triangles[t];
    int shortest = 0;
    double best = kInf;
    for (int k = 0; k < 3; ++k) {
      const double len = (mesh.vertices[tri[k]] - mesh.vertices[tri[(k + 1) % 3]]).norm();
      if (len < best) {
        best = len;
        shortest = k;
      }
    }
    const std::uint32_t a = find(tri[shortest]);
    const std::uint32_t b = find(tri[(shortest + 1) % 3]);
    if (a != b) {
      to[b] = a;
      ++collapsed;
    }
  }
  if (collapsed == 0) {
    return 0;
  }
  for (TriangleIndices& tri : mesh.triangles) {
    for (std::uint32_t& v : tri) {
      v = find(v);
    }
  }
  std::erase_if(mesh.triangles, [](const TriangleIndices& t) {
    return t[0] == t[1] || t[1] == t[2] || t[2] == t[0];
  });
  mesh.remove_unused_vertices();
  return collapsed;
}

// Removes back-to-back pairs (the same three vertices, opposite windings): a fin a collapse left.
std::size_t remove_back_to_back_pairs(TriangleMesh& mesh) {
  std::map<std::array<std::uint32_t, 3>, std::vector<std::size_t>> by_corners;
  for (std::size_t t = 0; t < mesh.triangle_count(); ++t) {
    std::array<std::uint32_t, 3> key = mesh.triangles[t];
    std::sort(key.begin(), key.end());
    by_corners[key].push_back(t);
  }
  std::vector<bool> drop(mesh.triangle_count(), false);
  std::size_t removed = 0;
  for (const auto& [key, list] : by_corners) {
    if (list.size() == 2) {
      drop[list[0]] = drop[list[1]] = true;
      removed += 2;
    }
  }
  if (removed > 0) {
    std::size_t i = 0;
    std::erase_if(mesh.triangles, [&](const TriangleIndices&) { return drop[i++]; });
    mesh.remove_unused_vertices();
  }
  return removed;
}

}  // namespace

std::size_t collapse_degenerate_triangles(TriangleMesh& mesh) {
  std::size_t collapsed = 0;
  for (int round = 0; round < 8; ++round) {  // a collapse can leave a new sliver beside it
    const std::size_t n = collapse_once(mesh);
    collapsed += n;
    if (n == 0) {
      break;
    }
  }
  return collapsed;
}

MeshSimplifyResult simplify_mesh(const TriangleMesh& source, const MeshSimplifyOptions& options) {
  if (options.target_vertices == 0) {
    throw Error("simplify", "the target vertex count must be > 0");
  }
  if (source.empty()) {
    throw Error("simplify", "the mesh has no triangles");
  }
  MeshSimplifyResult result;
  result.source_vertices = source.vertex_count();
  result.source_triangles = source.triangle_count();
  const MeshReport source_report = validate_mesh(source);
  if (source.vertex_count() <= options.target_vertices) {
    result.mesh = source;
    result.valid = source_report.closed && !source_report.has_defects();
    if (!result.valid) {
      result.problem =
          "the source itself is not a valid closed surface: " + source_report.summary();
    }
    return result;
  }

  const Box3 bounds = source.bounds();
  const Vec3 centre = bounds.center();
  std::vector<float> positions;
  positions.reserve(3 * source.vertex_count());
  for (const Vec3& v : source.vertices) {
    for (int k = 0; k < 3; ++k) {
      positions.push_back(static_cast<float>(v[k] - centre[k]));
    }
  }
  // meshoptimizer's errors are relative to this extent.
  const double extent_m = static_cast<double>(
      meshopt_simplifyScale(positions.data(), source.vertex_count(), 3 * sizeof(float)));
  std::vector<unsigned> indices;
  indices.reserve(3 * source.triangle_count());
  for (const TriangleIndices& t : source.triangles) {
    indices.insert(indices.end(), t.begin(), t.end());
  }

  // A closed surface has about twice as many triangles as vertices: start there, then shrink
  // the index budget until the result is within the vertex budget and still a valid closed
  // surface of the source's topology (Euler characteristic and component count).
  auto target_indices = static_cast<double>(6 * options.target_vertices);
  for (int attempt = 1; attempt <= options.max_attempts; ++attempt) {
    result.attempts = attempt;
    const auto budget =
        static_cast<std::size_t>(std::max(12.0, std::floor(target_indices / 3.0) * 3.0));
    TriangleMesh mesh =
        simplify_once(source, positions, indices, budget, extent_m, &result.simplifier_error_m);
    // meshoptimizer may leave a zero-area sliver or a fin on a flat region: tidy them up (the
    // result is then validated as a whole).
    collapse_degenerate_triangles(mesh);
    remove_back_to_back_pairs(mesh);
    // ... and fins at the source's sharp edges, which it does leave: flip them away.
    MeshReport report = validate_mesh(mesh);
    if (report.closed && report.folded_edges > source_report.folded_edges) {
      result.unfolded_edges = unfold_edges(mesh);
      report = validate_mesh(mesh);
    }
    const bool valid = report.closed && !report.has_defects() && report.signed_volume > 0.0 &&
                       report.components == source_report.components &&
                       report.euler_characteristic == source_report.euler_characteristic &&
                       report.folded_edges <= source_report.folded_edges;
    const bool within = mesh.vertex_count() <= options.target_vertices;
    result.mesh = std::move(mesh);
    result.valid = valid;
    if (valid && within) {
      result.problem.clear();
      break;
    }
    result.problem =
        !within
            ? "reached " + std::to_string(result.mesh.vertex_count()) + " vertices, over the target"
        : report.folded_edges > source_report.folded_edges
            ? "result has folds the source has not: " + report.summary()
            : "result not a valid closed surface of the source's topology: " + report.summary();
    // Over budget: scale the index budget by the overshoot; invalid: perturb it downwards.
    const double ratio = static_cast<double>(options.target_vertices) /
                         static_cast<double>(result.mesh.vertex_count());
    target_indices *= within ? 0.99 : std::min(0.99, ratio);
  }
  if (!result.problem.empty()) {
    result.valid = false;
  }
  result.mesh.compute_vertex_normals();
  return result;
}

}  // namespace hapsim
