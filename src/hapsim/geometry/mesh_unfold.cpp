#include "hapsim/geometry/mesh_unfold.h"

#include "hapsim/geometry/mesh_validation.h"

#include <algorithm>
#include <array>
#include <cstdint>
#include <optional>
#include <unordered_map>
#include <vector>

namespace hapsim {
namespace {

std::uint64_t directed(std::uint32_t a, std::uint32_t b) {
  return (static_cast<std::uint64_t>(a) << 32) | b;
}

// Triangles by directed edge, kept up to date across flips.
class EdgeIndex {
 public:
  explicit EdgeIndex(const TriangleMesh& mesh) {
    by_edge_.reserve(3 * mesh.triangle_count());
    for (std::size_t t = 0; t < mesh.triangle_count(); ++t) {
      add(mesh.triangles[t], t);
    }
  }
  void add(const TriangleIndices& tri, std::size_t t) {
    for (int k = 0; k < 3; ++k) {
      by_edge_[directed(tri[k], tri[(k + 1) % 3])] = t;
    }
  }
  void remove(const TriangleIndices& tri) {
    for (int k = 0; k < 3; ++k) {
      by_edge_.erase(directed(tri[k], tri[(k + 1) % 3]));
    }
  }
  /// The triangle traversing a -> b, or -1.
  [[nodiscard]] long long find(std::uint32_t a, std::uint32_t b) const {
    const auto it = by_edge_.find(directed(a, b));
    return it == by_edge_.end() ? -1 : static_cast<long long>(it->second);
  }

 private:
  std::unordered_map<std::uint64_t, std::size_t> by_edge_;
};

// Unit normal of a (not necessarily stored) triangle; zero when degenerate.
Vec3 unit_normal(const TriangleMesh& mesh, const TriangleIndices& tri, double area2_limit) {
  const Vec3 n = (mesh.vertices[tri[1]] - mesh.vertices[tri[0]])
                     .cross(mesh.vertices[tri[2]] - mesh.vertices[tri[0]]);
  const double length = n.norm();
  return length > area2_limit ? Vec3(n / length) : Vec3(Vec3::Zero());
}

// Whether a face with unit normal `n` traversing a -> b is folded against its neighbour across
// that edge (the triangle traversing b -> a).
bool folded_across(const TriangleMesh& mesh, const EdgeIndex& index, const Vec3& n, std::uint32_t a,
                   std::uint32_t b, double area2_limit) {
  const long long o = index.find(b, a);
  if (o < 0) {
    return false;
  }
  const Vec3 m = unit_normal(mesh, mesh.triangles[static_cast<std::size_t>(o)], area2_limit);
  return !m.isZero() && is_fold(n, m);
}

// Edge k of triangle t (a -> b, c opposite) and the triangle across it (b -> a, d opposite).
struct EdgeQuad {
  std::uint32_t a, b, c, d;
  std::size_t other;  // the triangle across the edge
};

std::optional<EdgeQuad> quad_across(const TriangleMesh& mesh, const EdgeIndex& index, std::size_t t,
                                    int k) {
  const TriangleIndices& t1 = mesh.triangles[t];
  const std::uint32_t a = t1[static_cast<std::size_t>(k)];
  const std::uint32_t b = t1[static_cast<std::size_t>((k + 1) % 3)];
  const long long o = index.find(b, a);
  if (o < 0 || static_cast<std::size_t>(o) == t) {
    return std::nullopt;
  }
  const TriangleIndices& t2 = mesh.triangles[static_cast<std::size_t>(o)];
  const std::uint32_t d = t2[0] != a && t2[0] != b   ? t2[0]
                          : t2[1] != a && t2[1] != b ? t2[1]
                                                     : t2[2];
  return EdgeQuad{a, b, t1[static_cast<std::size_t>((k + 2) % 3)], d, static_cast<std::size_t>(o)};
}

std::size_t flip_folds(TriangleMesh& mesh) {
  const double area2_limit = 1e-8 * mesh.bounds().diagonal().squaredNorm();
  EdgeIndex index(mesh);
  std::size_t flips = 0;
  // Each accepted flip lowers the fold count, so this ends; the pass bound is a safety net.
  for (int pass = 0; pass < 16; ++pass) {
    std::size_t flips_this_pass = 0;
    for (std::size_t t = 0; t < mesh.triangle_count(); ++t) {
      for (int k = 0; k < 3; ++k) {
        const std::optional<EdgeQuad> q = quad_across(mesh, index, t, k);
        if (!q) {
          continue;
        }
        const auto [a, b, c, d, t2_index] = *q;
        const TriangleIndices t1 = mesh.triangles[t];
        const TriangleIndices t2 = mesh.triangles[t2_index];
        const Vec3 n1 = unit_normal(mesh, t1, area2_limit);
        const Vec3 n2 = unit_normal(mesh, t2, area2_limit);
        if (n1.isZero() || n2.isZero() || !is_fold(n1, n2) || c == d || index.find(c, d) >= 0 ||
            index.find(d, c) >= 0) {
          continue;  // not a fold, or the other diagonal is already an edge (non-manifold)
        }
        // Faces a,b,c and b,a,d become a,d,c and d,b,c (the quad a-d-b-c's other diagonal).
        const TriangleIndices u1{a, d, c};
        const TriangleIndices u2{d, b, c};
        const Vec3 m1 = unit_normal(mesh, u1, area2_limit);
        const Vec3 m2 = unit_normal(mesh, u2, area2_limit);
        if (m1.isZero() || m2.isZero()) {
          continue;
        }
        // Folds among the five edges before (a-b and the quad's four sides) and after.
        const int before = 1 + folded_across(mesh, index, n1, b, c, area2_limit) +
                           folded_across(mesh, index, n1, c, a, area2_limit) +
                           folded_across(mesh, index, n2, a, d, area2_limit) +
                           folded_across(mesh, index, n2, d, b, area2_limit);
        const int after = static_cast<int>(is_fold(m1, m2)) +
                          folded_across(mesh, index, m1, a, d, area2_limit) +
                          folded_across(mesh, index, m1, c, a, area2_limit) +
                          folded_across(mesh, index, m2, d, b, area2_limit) +
                          folded_across(mesh, index, m2, b, c, area2_limit);
        if (after >= before) {
          continue;
        }
        index.remove(t1);
        index.remove(t2);
        mesh.triangles[t] = u1;
        mesh.triangles[t2_index] = u2;
        index.add(u1, t);
        index.add(u2, t2_index);
        ++flips_this_pass;
      }
    }
    flips += flips_this_pass;
    if (flips_this_pass == 0) {
      break;
    }
  }
  return flips;
}

// Folds no flip removes (a vertex pulled out into a spike) go by collapsing the folded edge onto
// one of its ends: kept when the mesh stays closed with the same Euler characteristic and has
// fewer folds. Returns the collapses.
std::size_t collapse_folds(TriangleMesh& mesh, const MeshReport& report_before) {
  std::size_t collapses = 0;
  MeshReport current = report_before;
  for (std::size_t t = 0; t < mesh.triangle_count() && current.folded_edges > 0; ++t) {
    const double area2_limit = 1e-8 * mesh.bounds().diagonal().squaredNorm();
    const EdgeIndex index(mesh);
    for (int k = 0; k < 3; ++k) {
      const std::optional<EdgeQuad> q = quad_across(mesh, index, t, k);
      if (!q) {
        continue;
      }
      const auto [a, b, c, d, other] = *q;
      const Vec3 n1 = unit_normal(mesh, mesh.triangles[t], area2_limit);
      const Vec3 n2 = unit_normal(mesh, mesh.triangles[other], area2_limit);
      if (n1.isZero() || n2.isZero() || !is_fold(n1, n2)) {
        continue;
      }
      // The fold edge itself first, then the fins' other edges (a sliver's short side).
      const std::array<std::pair<std::uint32_t, std::uint32_t>, 10> candidates{
          {{a, b}, {b, a}, {c, a}, {c, b}, {a, c}, {b, c}, {d, a}, {d, b}, {a, d}, {b, d}}};
      bool done = false;
      for (const auto& [from, to] : candidates) {
        TriangleMesh trial = mesh;
        for (TriangleIndices& tri : trial.triangles) {
          std::replace(tri.begin(), tri.end(), from, to);
        }
        std::erase_if(trial.triangles, [](const TriangleIndices& x) {
          return x[0] == x[1] || x[1] == x[2] || x[2] == x[0];
        });
        trial.remove_unused_vertices();
        const MeshReport r = validate_mesh(trial);
        if (r.closed && !r.has_defects() &&
            r.euler_characteristic == current.euler_characteristic &&
            r.folded_edges < current.folded_edges) {
          mesh = std::move(trial);
          current = r;
          ++collapses;
          done = true;
          break;
        }
      }
      if (done) {
        break;  // the triangle at t changed: the index is rebuilt for the next one
      }
    }
  }
  return collapses;
}

}  // namespace

std::size_t unfold_edges(TriangleMesh& mesh) {
  std::size_t changes = flip_folds(mesh);
  for (int round = 0; round < 4; ++round) {
    const MeshReport report = validate_mesh(mesh);
    if (report.folded_edges == 0 || !report.closed) {
      break;
    }
    const std::size_t collapsed = collapse_folds(mesh, report);
    if (collapsed == 0) {
      break;
    }
    changes += collapsed + flip_folds(mesh);
  }
  return changes;
}

}  // namespace hapsim
