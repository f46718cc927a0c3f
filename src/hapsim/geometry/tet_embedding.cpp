#include "hapsim/geometry/tet_embedding.h"

#include "hapsim/core/error.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include <Eigen/LU>

namespace hapsim {
namespace {

// A point counts as inside a tet when no barycentric coordinate is below −kEmbedInsideTolerance:
// a point on a shared face (or a hair outside from rounding) is then embedded with distance 0.
constexpr double kEmbedInsideTolerance = 1e-9;

bool embed_is_finite(const Vec3& v) {
  return std::isfinite(v.x()) && std::isfinite(v.y()) && std::isfinite(v.z());
}

// Closest point to p on triangle abc (Ericson, Real-Time Collision Detection §5.1.5).
Vec3 embed_closest_on_triangle(const Vec3& p, const Vec3& a, const Vec3& b, const Vec3& c) {
  const Vec3 ab = b - a;
  const Vec3 ac = c - a;
  const Vec3 ap = p - a;
  const double d1 = ab.dot(ap);
  const double d2 = ac.dot(ap);
  if (d1 <= 0.0 && d2 <= 0.0) {
    return a;
  }
  const Vec3 bp = p - b;
  const double d3 = ab.dot(bp);
  const double d4 = ac.dot(bp);
  if (d3 >= 0.0 && d4 <= d3) {
    return b;
  }
  const double vc = d1 * d4 - d3 * d2;
  if (vc <= 0.0 && d1 >= 0.0 && d3 <= 0.0) {
    return a + (d1 / (d1 - d3)) * ab;
  }
  const Vec3 cp = p - c;
  const double d5 = ab.dot(cp);
  const double d6 = ac.dot(cp);
  if (d6 >= 0.0 && d5 <= d6) {
    return c;
  }
  const double vb = d5 * d2 - d1 * d6;
  if (vb <= 0.0 && d2 >= 0.0 && d6 <= 0.0) {
    return a + (d2 / (d2 - d6)) * ac;
  }
  const double va = d3 * d6 - d5 * d4;
  if (va <= 0.0 && (d4 - d3) >= 0.0 && (d5 - d6) >= 0.0) {
    return b + ((d4 - d3) / ((d4 - d3) + (d5 - d6))) * (c - b);
  }
  const double denom = 1.0 / (va + vb + vc);
  return a + ab * (vb * denom) + ac * (vc * denom);
}

// Per usable tet: the map from a point to its barycentric coordinates.
struct EmbedTet {
  std::array<Vec3, 4> p;
  Mat3 inverse;  // of [p1−p0, p2−p0, p3−p0]
  Box3 box;
  bool usable = false;
};

std::array<double, 4> embed_barycentric(const EmbedTet& t, const Vec3& x) {
  const Vec3 l = t.inverse * (x - t.p[0]);
  return {1.0 - l.x() - l.y() - l.z(), l.x(), l.y(), l.z()};
}

// A uniform grid over the tets' bounding box; each cell lists the tets whose bounding box
// overlaps it (compressed rows).
class EmbedGrid {
 public:
  EmbedGrid(const std::vector<EmbedTet>& tets, const Box3& box) : lo_(box.min()) {
    std::size_t usable = 0;
    for (const EmbedTet& t : tets) {
      usable += t.usable ? 1u : 0u;
    }
    const Vec3 extent = box.diagonal();
    const double floor_extent = std::max(1e-9 * extent.norm(), 1e-300);
    const Vec3 e = extent.cwiseMax(Vec3::Constant(floor_extent));
    // About one tet per cell, at most 128 cells along an axis (2M cells).
    const double cell =
        std::cbrt(e.x() * e.y() * e.z() / static_cast<double>(std::max<std::size_t>(usable, 1)));
    for (int a = 0; a < 3; ++a) {
      const double n = std::ceil(e[a] / cell);
      dims_[static_cast<std::size_t>(a)] = static_cast<int>(std::clamp(n, 1.0, 128.0));
      h_[a] = e[a] / dims_[static_cast<std::size_t>(a)];
    }
    // Long thin tets (a hostile mesh) could each cover most cells: coarsen until the lists hold
    // at most ~32 entries per tet, so memory stays proportional to the mesh.
    while (coverage(tets) > 32 * usable + 1024 && (dims_[0] > 1 || dims_[1] > 1 || dims_[2] > 1)) {
      for (int a = 0; a < 3; ++a) {
        int& d = dims_[static_cast<std::size_t>(a)];
        d = std::max(1, d / 2);
        h_[a] = e[a] / d;
      }
    }
    const std::size_t cells = static_cast<std::size_t>(dims_[0]) *
                              static_cast<std::size_t>(dims_[1]) *
                              static_cast<std::size_t>(dims_[2]);
    start_.assign(cells + 1, 0);
    for (int pass = 0; pass < 2; ++pass) {
      for (std::size_t t = 0; t < tets.size(); ++t) {
        if (!tets[t].usable) {
          continue;
        }
        const Box3& tb = tets[t].box;
        const std::array<int, 3> c0 = cell_of(tb.min());
        const std::array<int, 3> c1 = cell_of(tb.max());
        for (int k = c0[2]; k <= c1[2]; ++k) {
          for (int j = c0[1]; j <= c1[1]; ++j) {
            for (int i = c0[0]; i <= c1[0]; ++i) {
              const std::size_t id = index(i, j, k);
              if (pass == 0) {
                ++start_[id + 1];
              } else {
                items_[fill_[id]++] = static_cast<std::uint32_t>(t);
              }
            }
          }
        }
      }
      if (pass == 0) {
        for (std::size_t c = 0; c < cells; ++c) {
          start_[c + 1] += start_[c];
        }
        items_.resize(start_[cells]);
        fill_.assign(start_.begin(), start_.end() - 1);
      }
    }
  }

  // How many (cell, tet) entries the current grid would hold.
  [[nodiscard]] std::size_t coverage(const std::vector<EmbedTet>& tets) const {
    std::size_t sum = 0;
    for (const EmbedTet& t : tets) {
      if (t.usable) {
        const std::array<int, 3> c0 = cell_of(t.box.min());
        const std::array<int, 3> c1 = cell_of(t.box.max());
        sum += static_cast<std::size_t>(c1[0] - c0[0] + 1) *
               static_cast<std::size_t>(c1[1] - c0[1] + 1) *
               static_cast<std::size_t>(c1[2] - c0[2] + 1);
      }
    }
    return sum;
  }

  [[nodiscard]] std::array<int, 3> cell_of(const Vec3& p) const {
    std::array<int, 3> c{};
    for (int a = 0; a < 3; ++a) {
      const double f = std::floor((p[a] - lo_[a]) / h_[a]);
      const double top = dims_[static_cast<std::size_t>(a)] - 1;
      c[static_cast<std::size_t>(a)] =
          static_cast<int>(std::isfinite(f) ? std::clamp(f, 0.0, top) : 0.0);
    }
    return c;
  }
  [[nodiscard]] std::size_t index(int i, int j, int k) const {
    return static_cast<std::size_t>(i) +
           static_cast<std::size_t>(dims_[0]) *
               (static_cast<std::size_t>(j) +
                static_cast<std::size_t>(dims_[1]) * static_cast<std::size_t>(k));
  }
  // The tets whose bounding box overlaps the cell holding x (x clamped into the grid).
  [[nodiscard]] std::span<const std::uint32_t> candidates(const Vec3& x) const {
    const std::array<int, 3> c = cell_of(x);
    const std::size_t id = index(c[0], c[1], c[2]);
    return {items_.data() + start_[id], items_.data() + start_[id + 1]};
  }

 private:
  Vec3 lo_;
  Vec3 h_ = Vec3::Ones();
  std::array<int, 3> dims_{1, 1, 1};
  std::vector<std::uint32_t> start_;
  std::vector<std::uint32_t> fill_;
  std::vector<std::uint32_t> items_;
};

// A bounding volume hierarchy over the boundary triangles, for the nearest one to a point
// outside the mesh (the nearest point of a union of tets to a point outside it is on its
// boundary).
class EmbedSurfaceTree {
 public:
  struct Triangle {
    std::array<Vec3, 3> p;
    std::uint32_t tet;
  };

  explicit EmbedSurfaceTree(std::vector<Triangle> triangles) : triangles_(std::move(triangles)) {
    if (!triangles_.empty()) {
      nodes_.reserve(2 * triangles_.size());  // a binary tree with leaves of ≥ 1 triangle
      nodes_.emplace_back();
      build(0, 0, triangles_.size());
    }
  }

  // The nearest triangle's tet and the distance to it; {0, inf} for an empty tree.
  [[nodiscard]] std::pair<std::uint32_t, double> nearest(const Vec3& x) const {
    std::uint32_t best_tet = 0;
    double best = kInf;
    if (nodes_.empty()) {
      return {best_tet, best};
    }
    std::vector<std::uint32_t> stack{0};
    while (!stack.empty()) {
      const Node& n = nodes_[stack.back()];
      stack.pop_back();
      if (n.box.exteriorDistance(x) >= best) {
        continue;
      }
      if (n.count > 0) {
        for (std::uint32_t i = n.first; i < n.first + n.count; ++i) {
          const Triangle& t = triangles_[i];
          const double d = (embed_closest_on_triangle(x, t.p[0], t.p[1], t.p[2]) - x).norm();
          if (d < best) {
            best = d;
            best_tet = t.tet;
          }
        }
        continue;
      }
      // Nearer child last, so it is searched first.
      const std::uint32_t a = n.first;
      const std::uint32_t b = n.first + 1;
      const bool a_nearer = nodes_[a].box.exteriorDistance(x) <= nodes_[b].box.exteriorDistance(x);
      stack.push_back(a_nearer ? b : a);
      stack.push_back(a_nearer ? a : b);
    }
    return {best_tet, best};
  }

 private:
  struct Node {
    Box3 box;
    std::uint32_t first = 0;  // leaf: first triangle; inner: first of two adjacent children
    std::uint32_t count = 0;  // triangles in a leaf, 0 for an inner node
  };

  // Fills node `slot` for triangles [begin, end).
  void build(std::size_t slot, std::size_t begin, std::size_t end) {
    Box3 box;
    Box3 centres;
    for (std::size_t i = begin; i < end; ++i) {
      for (const Vec3& p : triangles_[i].p) {
        box.extend(p);
      }
      centres.extend((triangles_[i].p[0] + triangles_[i].p[1] + triangles_[i].p[2]) / 3.0);
    }
    nodes_[slot].box = box;
    constexpr std::size_t kLeafSize = 4;
    if (end - begin <= kLeafSize) {
      nodes_[slot].first = static_cast<std::uint32_t>(begin);
      nodes_[slot].count = static_cast<std::uint32_t>(end - begin);
      return;
    }
    Eigen::Index axis = 0;
    centres.diagonal().maxCoeff(&axis);
    const std::size_t mid = begin + (end - begin) / 2;
    std::nth_element(triangles_.begin() + static_cast<std::ptrdiff_t>(begin),
                     triangles_.begin() + static_cast<std::ptrdiff_t>(mid),
                     triangles_.begin() + static_cast<std::ptrdiff_t>(end),
                     [axis](const Triangle& x, const Triangle& y) {
                       return x.p[0][axis] + x.p[1][axis] + x.p[2][axis] <
                              y.p[0][axis] + y.p[1][axis] + y.p[2][axis];
                     });
    const std::size_t children = nodes_.size();  // two adjacent slots
    nodes_.emplace_back();
    nodes_.emplace_back();
    nodes_[slot].first = static_cast<std::uint32_t>(children);
    build(children, begin, mid);
    build(children + 1, mid, end);
  }

  std::vector<Triangle> triangles_;
  std::vector<Node> nodes_;
};

}  // namespace

std::vector<TetEmbedding> embed_points(const TetMesh& mesh, std::span<const Vec3> points) {
  // Usable tets: in range, finite, not flat (their barycentric map exists).
  std::vector<EmbedTet> tets(mesh.tets.size());
  Box3 box;
  std::size_t usable = 0;
  for (std::size_t t = 0; t < mesh.tets.size(); ++t) {
    const TetIndices& idx = mesh.tets[t];
    EmbedTet& e = tets[t];
    bool ok = true;
    for (std::size_t k = 0; k < 4 && ok; ++k) {
      ok = idx[k] < mesh.nodes.size() && embed_is_finite(mesh.nodes[idx[k]]);
      if (ok) {
        e.p[k] = mesh.nodes[idx[k]];
      }
    }
    if (!ok) {
      continue;
    }
    Mat3 edges;
    edges << e.p[1] - e.p[0], e.p[2] - e.p[0], e.p[3] - e.p[0];
    bool invertible = false;
    double determinant = 0.0;
    edges.computeInverseAndDetWithCheck(e.inverse, determinant, invertible, 0.0);
    const double scale = edges.colwise().norm().prod();
    e.usable = invertible && std::abs(determinant) > 1e-12 * scale && e.inverse.allFinite();
    if (e.usable) {
      ++usable;
      for (const Vec3& p : e.p) {
        e.box.extend(p);
      }
      box.extend(e.box);
    }
  }
  if (usable == 0) {
    throw Error("tet embedding", "the mesh has no usable tetrahedra to embed points in");
  }
  const EmbedGrid grid(tets, box);

  std::vector<EmbedSurfaceTree::Triangle> triangles;
  {
    const TetBoundary boundary = tet_boundary(mesh);
    triangles.reserve(boundary.surface.triangles.size());
    for (std::size_t t = 0; t < boundary.surface.triangles.size(); ++t) {
      const std::uint32_t tet = boundary.tet_of_triangle[t];
      if (tets[tet].usable) {
        triangles.push_back({boundary.surface.corners(t), tet});
      }
    }
  }
  const EmbedSurfaceTree surface(std::move(triangles));

  std::vector<TetEmbedding> out(points.size());
  for (std::size_t i = 0; i < points.size(); ++i) {
    const Vec3& x = points[i];
    TetEmbedding& e = out[i];
    if (!embed_is_finite(x)) {
      e.distance_m = kInf;  // nothing to tie it to: tet 0 with zero weights, and said so
      continue;
    }
    // Inside: of the tets containing x (two or more on a shared face or edge), the one it is
    // deepest in. A containing tet's bounding box holds x, so it is listed in x's cell.
    double deepest = -kInf;
    for (const std::uint32_t t : grid.candidates(x)) {
      if (!tets[t].box.contains(x)) {
        continue;
      }
      const std::array<double, 4> b = embed_barycentric(tets[t], x);
      const double smallest = *std::min_element(b.begin(), b.end());
      if (smallest >= -kEmbedInsideTolerance && smallest > deepest) {
        deepest = smallest;
        e.tet = t;
        e.barycentric = b;
      }
    }
    if (deepest > -kInf) {
      continue;
    }
    // Outside every tet: the nearest boundary triangle's tet, its coordinates extrapolated.
    const auto [tet, distance] = surface.nearest(x);
    e.tet = tet;
    e.barycentric = embed_barycentric(tets[tet], x);
    e.distance_m = distance;
  }
  return out;
}

}  // namespace hapsim
