#include "hapsim/geometry/tet_mesh.h"

#include "hapsim/core/error.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <numbers>
#include <numeric>

namespace hapsim {
namespace {

bool tet_is_finite(const Vec3& v) {
  return std::isfinite(v.x()) && std::isfinite(v.y()) && std::isfinite(v.z());
}

double tet_signed_volume_of(const Vec3& a, const Vec3& b, const Vec3& c, const Vec3& d) {
  return (b - a).dot((c - a).cross(d - a)) / 6.0;
}

// Outward faces of a positively oriented tet: face k is the one opposite node k.
constexpr std::array<std::array<int, 3>, 4> kTetOutwardFaces{
    {{1, 2, 3}, {0, 3, 2}, {0, 1, 3}, {0, 2, 1}}};

std::string tet_format_number(double x) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.3g", x);
  return buf;
}

class TetUnionFind {
 public:
  explicit TetUnionFind(std::size_t n) : parent_(n) {
    std::iota(parent_.begin(), parent_.end(), std::uint32_t{0});
  }
  std::uint32_t find(std::uint32_t x) {
    while (parent_[x] != x) {
      parent_[x] = parent_[parent_[x]];  // path halving: near O(1) without recursion
      x = parent_[x];
    }
    return x;
  }
  void unite(std::uint32_t a, std::uint32_t b) {
    a = find(a);
    b = find(b);
    if (a != b) {
      parent_[std::max(a, b)] = std::min(a, b);
    }
  }

 private:
  std::vector<std::uint32_t> parent_;
};

bool tet_in_range(const TetIndices& t, std::size_t node_count) {
  return t[0] < node_count && t[1] < node_count && t[2] < node_count && t[3] < node_count;
}

// The volume below which a tet counts as flat: relative to the mesh's size so that a mesh in
// millimetres and one in metres agree.
double tet_degenerate_volume(const TetMesh& mesh) {
  const Box3 b = mesh.bounds();
  if (b.isEmpty()) {
    return 0.0;
  }
  const double diag = b.diagonal().norm();
  return 1e-12 * diag * diag * diag;
}

// Unites the nodes of every in-range tet; returns the union-find over nodes.
TetUnionFind tet_node_components(const TetMesh& mesh) {
  TetUnionFind uf(mesh.nodes.size());
  for (const TetIndices& t : mesh.tets) {
    if (tet_in_range(t, mesh.nodes.size())) {
      uf.unite(t[0], t[1]);
      uf.unite(t[0], t[2]);
      uf.unite(t[0], t[3]);
    }
  }
  return uf;
}

std::uint64_t tet_edge_key(std::uint32_t a, std::uint32_t b) {
  return (std::uint64_t{std::min(a, b)} << 32) | std::max(a, b);
}

// The edges (tet_edge_key, sorted) of the boundary of the tets not `dropped` that are not
// shared by exactly two boundary triangles in opposite directions: where dropping tets would
// leave the surface open or non-manifold.
std::vector<std::uint64_t> tet_ball_bad_surface_edges(const TetMesh& mesh,
                                                      const std::vector<char>& dropped) {
  TetMesh kept;
  kept.nodes = mesh.nodes;
  for (std::size_t t = 0; t < mesh.tets.size(); ++t) {
    if (!dropped[t]) {
      kept.tets.push_back(mesh.tets[t]);
    }
  }
  const TetBoundary b = tet_boundary(kept);
  // Per edge use: the key and whether it runs from the smaller node to the larger.
  std::vector<std::pair<std::uint64_t, bool>> uses;
  for (const TriangleIndices& tri : b.surface.triangles) {
    for (std::size_t k = 0; k < 3; ++k) {
      const std::uint32_t from = b.node_of_vertex[tri[k]];
      const std::uint32_t to = b.node_of_vertex[tri[(k + 1) % 3]];
      uses.emplace_back(tet_edge_key(from, to), from < to);
    }
  }
  std::sort(uses.begin(), uses.end());
  std::vector<std::uint64_t> bad;
  for (std::size_t i = 0; i < uses.size();) {
    std::size_t j = i;
    while (j < uses.size() && uses[j].first == uses[i].first) {
      ++j;
    }
    if (j - i != 2 || uses[i].second == uses[i + 1].second) {
      bad.push_back(uses[i].first);
    }
    i = j;
  }
  return bad;
}

// Tets that overlap through a shared face, in a mesh whose tets are all in range and positively
// oriented: two tets on a face must lie on its two sides (they traverse it in opposite
// directions), and no face joins more than two. A duplicated tet is the commonest case (a file
// listing an element twice). Names the smallest element index that is the later of such a pair.
std::optional<TetMeshProblem> tet_find_overlap(const TetMesh& mesh) {
  struct FaceUse {
    std::array<std::uint32_t, 3> key;  // sorted
    std::uint32_t tet;
    bool odd;  // the winding, as the parity of the permutation that sorts the face
  };
  std::vector<FaceUse> uses;
  uses.reserve(4 * mesh.tets.size());
  for (std::size_t t = 0; t < mesh.tets.size(); ++t) {
    const TetIndices& tet = mesh.tets[t];
    for (const auto& local : kTetOutwardFaces) {
      std::array<std::uint32_t, 3> key{tet[static_cast<std::size_t>(local[0])],
                                       tet[static_cast<std::size_t>(local[1])],
                                       tet[static_cast<std::size_t>(local[2])]};
      bool odd = false;
      for (const auto& [i, j] : {std::pair{0, 1}, std::pair{1, 2}, std::pair{0, 1}}) {
        if (key[static_cast<std::size_t>(i)] > key[static_cast<std::size_t>(j)]) {
          std::swap(key[static_cast<std::size_t>(i)], key[static_cast<std::size_t>(j)]);
          odd = !odd;
        }
      }
      uses.push_back({key, static_cast<std::uint32_t>(t), odd});
    }
  }
  std::sort(uses.begin(), uses.end(), [](const FaceUse& x, const FaceUse& y) {
    return x.key != y.key ? x.key < y.key : x.tet < y.tet;
  });
  std::optional<TetMeshProblem> first;
  for (std::size_t i = 0; i < uses.size();) {
    std::size_t j = i + 1;
    while (j < uses.size() && uses[j].key == uses[i].key) {
      ++j;
    }
    const std::size_t count = j - i;
    const bool same_side = count == 2 && uses[i].odd == uses[i + 1].odd;
    if (count > 2 || same_side) {
      const std::uint32_t later = uses[j - 1].tet;
      if (!first || later < *first->element) {
        const std::array<std::uint32_t, 3>& f = uses[i].key;
        const std::string face = "nodes " + std::to_string(f[0]) + ", " + std::to_string(f[1]) +
                                 ", " + std::to_string(f[2]);
        TetIndices a = mesh.tets[uses[i].tet];
        TetIndices b = mesh.tets[later];
        std::sort(a.begin(), a.end());
        std::sort(b.begin(), b.end());
        std::string message = "element " + std::to_string(later) + ": ";
        if (count > 2) {
          message += "its face (" + face + ") is shared by " + std::to_string(count) +
                     " elements; a face joins at most two";
        } else if (a == b) {
          message += "duplicates element " + std::to_string(uses[i].tet) + " (the same nodes)";
        } else {
          message += "overlaps element " + std::to_string(uses[i].tet) +
                     " (both on the same side of their shared face, " + face + ")";
        }
        first = TetMeshProblem{message, later};
      }
    }
    i = j;
  }
  return first;
}

}  // namespace

double TetMesh::signed_volume(std::size_t t) const {
  const TetIndices& tet = tets[t];
  return tet_signed_volume_of(nodes[tet[0]], nodes[tet[1]], nodes[tet[2]], nodes[tet[3]]);
}

double TetMesh::volume() const {
  double sum = 0.0;
  for (std::size_t t = 0; t < tets.size(); ++t) {
    sum += signed_volume(t);
  }
  return sum;
}

Box3 TetMesh::bounds() const {
  Box3 box;
  for (const Vec3& p : nodes) {
    if (tet_is_finite(p)) {
      box.extend(p);
    }
  }
  return box;
}

void TetMesh::scale(double factor) {
  for (Vec3& p : nodes) {
    p *= factor;
  }
}

void TetMesh::transform(const Iso3& X_new_old) {
  for (Vec3& p : nodes) {
    p = X_new_old * p;
  }
}

TetBoundary tet_boundary(const TetMesh& mesh) {
  struct FaceUse {
    std::array<std::uint32_t, 3> key;  // sorted node indices
    std::uint32_t use;                 // 4·tet + face
  };
  const std::size_t node_count = mesh.nodes.size();
  std::vector<FaceUse> uses;
  uses.reserve(4 * mesh.tets.size());
  for (std::size_t t = 0; t < mesh.tets.size(); ++t) {
    const TetIndices& tet = mesh.tets[t];
    if (!tet_in_range(tet, node_count)) {
      continue;
    }
    for (std::uint32_t f = 0; f < 4; ++f) {
      const auto& local = kTetOutwardFaces[f];
      std::array<std::uint32_t, 3> key{tet[static_cast<std::size_t>(local[0])],
                                       tet[static_cast<std::size_t>(local[1])],
                                       tet[static_cast<std::size_t>(local[2])]};
      std::sort(key.begin(), key.end());
      uses.push_back({key, static_cast<std::uint32_t>(4 * t + f)});
    }
  }
  std::sort(uses.begin(), uses.end(), [](const FaceUse& x, const FaceUse& y) {
    return x.key != y.key ? x.key < y.key : x.use < y.use;
  });

  // A face used exactly once is on the boundary; keep them in tet order for a stable output.
  std::vector<std::uint32_t> boundary_uses;
  for (std::size_t i = 0; i < uses.size();) {
    std::size_t j = i + 1;
    while (j < uses.size() && uses[j].key == uses[i].key) {
      ++j;
    }
    if (j == i + 1) {
      boundary_uses.push_back(uses[i].use);
    }
    i = j;
  }
  std::sort(boundary_uses.begin(), boundary_uses.end());

  TetBoundary out;
  constexpr std::uint32_t kUnset = std::numeric_limits<std::uint32_t>::max();
  std::vector<std::uint32_t> vertex_of_node(node_count, kUnset);
  for (const std::uint32_t use : boundary_uses) {
    const TetIndices& tet = mesh.tets[use / 4];
    for (const int local : kTetOutwardFaces[use % 4]) {
      vertex_of_node[tet[static_cast<std::size_t>(local)]] = 0;  // mark; numbered below
    }
  }
  // Surface vertices in ascending node order: deterministic and easy to map back.
  for (std::size_t n = 0; n < node_count; ++n) {
    if (vertex_of_node[n] != kUnset) {
      vertex_of_node[n] = static_cast<std::uint32_t>(out.node_of_vertex.size());
      out.node_of_vertex.push_back(static_cast<std::uint32_t>(n));
      out.surface.vertices.push_back(mesh.nodes[n]);
    }
  }
  out.surface.triangles.reserve(boundary_uses.size());
  out.tet_of_triangle.reserve(boundary_uses.size());
  for (const std::uint32_t use : boundary_uses) {
    out.tet_of_triangle.push_back(use / 4);
    const TetIndices& tet = mesh.tets[use / 4];
    const auto& local = kTetOutwardFaces[use % 4];
    out.surface.triangles.push_back({vertex_of_node[tet[static_cast<std::size_t>(local[0])]],
                                     vertex_of_node[tet[static_cast<std::size_t>(local[1])]],
                                     vertex_of_node[tet[static_cast<std::size_t>(local[2])]]});
  }
  return out;
}

TetMeshQuality tet_mesh_quality(const TetMesh& mesh) {
  TetMeshQuality q;
  q.tets = mesh.tets.size();
  q.nodes = mesh.nodes.size();
  const double degenerate_volume = tet_degenerate_volume(mesh);

  std::vector<char> used(mesh.nodes.size(), 0);
  double min_dihedral = kInf;
  double max_dihedral = -kInf;
  double max_aspect = 0.0;
  double min_volume = kInf;
  bool any_measured = false;
  for (std::size_t t = 0; t < mesh.tets.size(); ++t) {
    const TetIndices& tet = mesh.tets[t];
    if (!tet_in_range(tet, mesh.nodes.size())) {
      ++q.out_of_range;
      continue;
    }
    for (const std::uint32_t n : tet) {
      used[n] = 1;
    }
    const std::array<Vec3, 4> p{mesh.nodes[tet[0]], mesh.nodes[tet[1]], mesh.nodes[tet[2]],
                                mesh.nodes[tet[3]]};
    if (!(tet_is_finite(p[0]) && tet_is_finite(p[1]) && tet_is_finite(p[2]) &&
          tet_is_finite(p[3]))) {
      ++q.non_finite;
      continue;
    }
    const double v = tet_signed_volume_of(p[0], p[1], p[2], p[3]);
    q.total_volume_m3 += v;
    min_volume = std::min(min_volume, v);
    any_measured = true;
    if (std::abs(v) <= degenerate_volume) {
      ++q.degenerate;
      continue;  // no angles or inradius to speak of
    }
    if (v < 0.0) {
      ++q.inverted;
    }
    // Outward (for a positive tet) face normals, length = twice the face's area.
    std::array<Vec3, 4> n2;
    double area_sum = 0.0;
    for (std::size_t f = 0; f < 4; ++f) {
      const auto& local = kTetOutwardFaces[f];
      const Vec3& a = p[static_cast<std::size_t>(local[0])];
      n2[f] = (p[static_cast<std::size_t>(local[1])] - a)
                  .cross(p[static_cast<std::size_t>(local[2])] - a);
      area_sum += 0.5 * n2[f].norm();
    }
    // The dihedral angle at the edge shared by faces k and l is π minus the angle between their
    // outward normals (an inverted tet flips both normals, which leaves the angle unchanged).
    double longest_edge = 0.0;
    for (std::size_t k = 0; k < 4; ++k) {
      for (std::size_t l = k + 1; l < 4; ++l) {
        const double c = n2[k].dot(n2[l]) / (n2[k].norm() * n2[l].norm());
        const double dihedral = std::numbers::pi - std::acos(std::clamp(c, -1.0, 1.0));
        min_dihedral = std::min(min_dihedral, dihedral);
        max_dihedral = std::max(max_dihedral, dihedral);
        longest_edge = std::max(longest_edge, (p[k] - p[l]).norm());
      }
    }
    const double inradius = 3.0 * std::abs(v) / area_sum;
    max_aspect = std::max(max_aspect, longest_edge / (2.0 * std::sqrt(6.0) * inradius));
  }
  if (std::isfinite(min_dihedral)) {
    q.min_dihedral_deg = min_dihedral * 180.0 / std::numbers::pi;
    q.max_dihedral_deg = max_dihedral * 180.0 / std::numbers::pi;
  }
  q.max_aspect_ratio = max_aspect;
  q.min_volume_m3 = any_measured ? min_volume : 0.0;
  q.unused_nodes = static_cast<std::size_t>(std::count(used.begin(), used.end(), 0));

  TetUnionFind uf = tet_node_components(mesh);
  for (std::size_t n = 0; n < mesh.nodes.size(); ++n) {
    if (used[n] && uf.find(static_cast<std::uint32_t>(n)) == n) {
      ++q.components;
    }
  }
  return q;
}

std::optional<TetMeshProblem> find_tet_mesh_problem(const TetMesh& mesh, bool allow_disconnected) {
  if (mesh.tets.empty()) {
    return TetMeshProblem{"the mesh has no tetrahedra", std::nullopt};
  }
  if (!mesh.regions.empty() && mesh.regions.size() != mesh.tets.size()) {
    return TetMeshProblem{std::to_string(mesh.regions.size()) + " region values for " +
                              std::to_string(mesh.tets.size()) +
                              " elements; expected one per element (or none)",
                          std::nullopt};
  }
  const std::size_t node_count = mesh.nodes.size();
  const double degenerate_volume = tet_degenerate_volume(mesh);
  for (std::size_t t = 0; t < mesh.tets.size(); ++t) {
    const TetIndices& tet = mesh.tets[t];
    const std::string element = "element " + std::to_string(t) + ": ";
    for (const std::uint32_t n : tet) {
      if (n >= node_count) {
        return TetMeshProblem{element + "node " + std::to_string(n) +
                                  " out of range (the mesh has " + std::to_string(node_count) +
                                  " nodes)",
                              t};
      }
    }
    for (const std::uint32_t n : tet) {
      if (!tet_is_finite(mesh.nodes[n])) {
        return TetMeshProblem{element + "node " + std::to_string(n) + " is not finite", t};
      }
    }
    const double v = mesh.signed_volume(t);
    if (!std::isfinite(v)) {  // finite nodes whose products overflow (beyond ~1e100 m)
      return TetMeshProblem{element + "its volume overflows (coordinates too large)", t};
    }
    if (std::abs(v) <= degenerate_volume) {
      return TetMeshProblem{element + "degenerate (volume " + tet_format_number(v) + " m^3)", t};
    }
    if (v < 0.0) {
      return TetMeshProblem{element + "inverted (signed volume " + tet_format_number(v) + " m^3)",
                            t};
    }
  }
  if (auto overlap = tet_find_overlap(mesh)) {
    return overlap;
  }
  if (allow_disconnected) {
    return std::nullopt;
  }
  TetUnionFind uf = tet_node_components(mesh);
  const std::uint32_t root0 = uf.find(mesh.tets[0][0]);
  std::size_t first_apart = 0;
  std::vector<char> is_root(node_count, 0);
  for (std::size_t t = 0; t < mesh.tets.size(); ++t) {
    const std::uint32_t r = uf.find(mesh.tets[t][0]);
    is_root[r] = 1;
    if (r != root0 && first_apart == 0) {
      first_apart = t;
    }
  }
  if (first_apart != 0) {
    const auto pieces = std::count(is_root.begin(), is_root.end(), 1);
    return TetMeshProblem{std::to_string(pieces) + " disconnected pieces (element 0 and element " +
                              std::to_string(first_apart) +
                              " are not connected); one body is one piece",
                          std::nullopt};
  }
  return std::nullopt;
}

void validate_tet_mesh(const TetMesh& mesh, std::string_view source, bool allow_disconnected) {
  if (const auto problem = find_tet_mesh_problem(mesh, allow_disconnected)) {
    throw Error(std::string(source), problem->message);
  }
}

TetMesh make_tet_block(const Vec3& size_m, const std::array<int, 3>& cells) {
  const int nx = std::max(cells[0], 1);
  const int ny = std::max(cells[1], 1);
  const int nz = std::max(cells[2], 1);
  TetMesh mesh;
  const auto node = [&](int i, int j, int k) {
    return static_cast<std::uint32_t>(i + (nx + 1) * (j + (ny + 1) * k));
  };
  mesh.nodes.reserve(static_cast<std::size_t>(nx + 1) * static_cast<std::size_t>(ny + 1) *
                     static_cast<std::size_t>(nz + 1));
  for (int k = 0; k <= nz; ++k) {
    for (int j = 0; j <= ny; ++j) {
      for (int i = 0; i <= nx; ++i) {
        mesh.nodes.emplace_back(size_m.x() * i / nx, size_m.y() * j / ny, size_m.z() * k / nz);
      }
    }
  }
  // The six monotone paths from corner 000 to 111 (one per permutation of the axes); each path's
  // four corners are one tet. Odd permutations are mirror images, so two nodes are swapped to keep
  // every tet positively oriented.
  struct Path {
    std::array<int, 3> axes;
    bool odd;
  };
  constexpr std::array<Path, 6> kPaths{{{{0, 1, 2}, false},
                                        {{1, 2, 0}, false},
                                        {{2, 0, 1}, false},
                                        {{0, 2, 1}, true},
                                        {{2, 1, 0}, true},
                                        {{1, 0, 2}, true}}};
  mesh.tets.reserve(6 * static_cast<std::size_t>(nx) * static_cast<std::size_t>(ny) *
                    static_cast<std::size_t>(nz));
  for (int k = 0; k < nz; ++k) {
    for (int j = 0; j < ny; ++j) {
      for (int i = 0; i < nx; ++i) {
        for (const Path& path : kPaths) {
          std::array<int, 3> c{i, j, k};
          TetIndices tet{};
          tet[0] = node(c[0], c[1], c[2]);
          for (std::size_t s = 0; s < 3; ++s) {
            ++c[static_cast<std::size_t>(path.axes[s])];
            tet[s + 1] = node(c[0], c[1], c[2]);
          }
          if (path.odd) {
            std::swap(tet[1], tet[2]);
          }
          mesh.tets.push_back(tet);
        }
      }
    }
  }
  return mesh;
}

TetMesh make_tet_ball(double radius_m, std::size_t target_tets) {
  // About π·n³ tets come from the cubes wholly inside the ball of an n³ grid over its bounding
  // cube. n is even so that no cube straddles a coordinate plane: the kept cubes then form a
  // staircase without cubes touching at an edge or corner only. n ≥ 4 keeps at least 8 cubes.
  const double wanted = std::max(static_cast<double>(target_tets), 1.0) / std::numbers::pi;
  int n = static_cast<int>(std::ceil(std::cbrt(wanted)));
  n = std::clamp(n + (n % 2), 4, 512);
  const double r = std::abs(radius_m) > 0.0 && std::isfinite(radius_m) ? std::abs(radius_m) : 1.0;
  const TetMesh grid = make_tet_block(Vec3::Constant(2.0 * r), {n, n, n});
  const Vec3 centre = Vec3::Constant(r);
  const double inside_r = r * (1.0 + 1e-9);

  // Keep the six tets of every cube whose eight corners are in the ball (tets are emitted 6 per
  // cube, cube by cube).
  std::vector<char> keep_node(grid.nodes.size(), 0);
  TetMesh ball;
  for (std::size_t c = 0; c < grid.tets.size() / 6; ++c) {
    bool inside = true;
    for (std::size_t t = 6 * c; t < 6 * c + 6 && inside; ++t) {
      for (const std::uint32_t v : grid.tets[t]) {
        inside = inside && (grid.nodes[v] - centre).norm() <= inside_r;
      }
    }
    if (inside) {
      for (std::size_t t = 6 * c; t < 6 * c + 6; ++t) {
        ball.tets.push_back(grid.tets[t]);
        for (const std::uint32_t v : grid.tets[t]) {
          keep_node[v] = 1;
        }
      }
    }
  }
  std::vector<std::uint32_t> new_index(grid.nodes.size(), 0);
  for (std::size_t v = 0; v < grid.nodes.size(); ++v) {
    if (keep_node[v]) {
      new_index[v] = static_cast<std::uint32_t>(ball.nodes.size());
      ball.nodes.push_back(grid.nodes[v] - centre);
    }
  }
  for (TetIndices& tet : ball.tets) {
    for (std::uint32_t& v : tet) {
      v = new_index[v];
    }
  }

  // Project the staircase's boundary nodes radially onto the sphere. A tet that this squashes
  // (to less than a fifth of its volume) is a sliver on a step's edge: when all four of its nodes
  // are on the boundary it is dropped (the faces under it become boundary, over the same nodes),
  // unless dropping it would leave an edge of the surface without exactly two triangles.
  // Otherwise its boundary nodes move back towards the staircase, halving the step each round;
  // after the halving rounds any tet still squashed puts its nodes back on the staircase, which
  // is always valid (each such round zeroes at least one step, so this ends).
  const TetBoundary boundary = tet_boundary(ball);
  const std::vector<Vec3> rest = ball.nodes;
  std::vector<double> rest_volume(ball.tets.size());
  for (std::size_t t = 0; t < ball.tets.size(); ++t) {
    rest_volume[t] = ball.signed_volume(t);
  }
  std::vector<char> on_boundary(ball.nodes.size(), 0);
  for (const std::uint32_t node : boundary.node_of_vertex) {
    on_boundary[node] = 1;
    const Vec3& p = rest[node];
    ball.nodes[node] = p * (r / p.norm());  // never the centre: n ≥ 4 keeps it inside
  }
  const auto squashed = [&](std::size_t t) { return ball.signed_volume(t) < 0.2 * rest_volume[t]; };
  std::vector<char> dropped(ball.tets.size(), 0);
  std::vector<char> keep_anyway(ball.tets.size(), 0);
  while (true) {
    for (std::size_t t = 0; t < ball.tets.size(); ++t) {
      const TetIndices& tet = ball.tets[t];
      dropped[t] = !keep_anyway[t] && squashed(t) && on_boundary[tet[0]] && on_boundary[tet[1]] &&
                   on_boundary[tet[2]] && on_boundary[tet[3]];
    }
    const std::vector<std::uint64_t> bad_edges = tet_ball_bad_surface_edges(ball, dropped);
    bool changed = false;
    for (std::size_t t = 0; t < ball.tets.size(); ++t) {
      if (!dropped[t]) {
        continue;
      }
      const TetIndices& tet = ball.tets[t];
      for (std::size_t i = 0; i < 4 && !keep_anyway[t]; ++i) {
        for (std::size_t j = i + 1; j < 4; ++j) {
          if (std::binary_search(bad_edges.begin(), bad_edges.end(),
                                 tet_edge_key(tet[i], tet[j]))) {
            keep_anyway[t] = 1;
            changed = true;
            break;
          }
        }
      }
    }
    if (!changed) {
      break;  // the surface is manifold, or no dropped tet is to blame
    }
  }

  std::vector<double> step(ball.nodes.size(), 0.0);
  for (const std::uint32_t node : boundary.node_of_vertex) {
    step[node] = 1.0;
  }
  constexpr int kHalvingRounds = 8;
  for (int round = 0;; ++round) {
    for (const std::uint32_t node : boundary.node_of_vertex) {
      const Vec3& p = rest[node];
      ball.nodes[node] = p + step[node] * (p * (r / p.norm()) - p);
    }
    bool all_good = true;
    for (std::size_t t = 0; t < ball.tets.size(); ++t) {
      if (dropped[t] || !squashed(t)) {
        continue;
      }
      all_good = false;
      for (const std::uint32_t v : ball.tets[t]) {
        step[v] = round < kHalvingRounds ? 0.5 * step[v] : 0.0;
      }
    }
    if (all_good) {
      break;
    }
  }

  // Drop the tets, then the nodes only they used.
  std::size_t kept = 0;
  for (std::size_t t = 0; t < ball.tets.size(); ++t) {
    if (!dropped[t]) {
      ball.tets[kept++] = ball.tets[t];
    }
  }
  ball.tets.resize(kept);
  constexpr std::uint32_t kUnused = std::numeric_limits<std::uint32_t>::max();
  std::vector<std::uint32_t> renumber(ball.nodes.size(), kUnused);
  for (const TetIndices& tet : ball.tets) {
    for (const std::uint32_t v : tet) {
      renumber[v] = 0;
    }
  }
  std::size_t used = 0;
  for (std::size_t v = 0; v < ball.nodes.size(); ++v) {
    if (renumber[v] != kUnused) {
      renumber[v] = static_cast<std::uint32_t>(used);
      ball.nodes[used++] = ball.nodes[v];
    }
  }
  ball.nodes.resize(used);
  for (TetIndices& tet : ball.tets) {
    for (std::uint32_t& v : tet) {
      v = renumber[v];
    }
  }
  return ball;
}

}  // namespace hapsim
