#include "hapsim/geometry/mesh_validation.h"

#include <nlohmann/json.hpp>

#include <algorithm>
#include <cmath>
#include <numbers>
#include <numeric>
#include <sstream>

namespace hapsim {
namespace {

bool is_finite(const Vec3& v) {
  return std::isfinite(v.x()) && std::isfinite(v.y()) && std::isfinite(v.z());
}

bool in_range(const TriangleIndices& t, std::size_t vertex_count) {
  return t[0] < vertex_count && t[1] < vertex_count && t[2] < vertex_count;
}

bool repeats_index(const TriangleIndices& t) {
  return t[0] == t[1] || t[1] == t[2] || t[0] == t[2];
}

class UnionFind {
 public:
  explicit UnionFind(std::size_t n) : parent_(n) { std::iota(parent_.begin(), parent_.end(), 0u); }
  std::uint32_t find(std::uint32_t x) {
    while (parent_[x] != x) {
      parent_[x] = parent_[parent_[x]];  // path halving keeps it near O(1) without recursion
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

// One directed use of an undirected edge by a triangle.
struct EdgeUse {
  std::uint64_t key;  // (min << 32) | max
  std::uint32_t tri;  // triangle index
  bool forward;       // the triangle traverses min -> max
};

std::vector<EdgeUse> collect_edge_uses(const TriangleMesh& mesh,
                                       const std::vector<char>& in_topology) {
  std::vector<EdgeUse> uses;
  uses.reserve(3 * mesh.triangles.size());
  for (std::size_t t = 0; t < mesh.triangles.size(); ++t) {
    if (!in_topology[t]) {
      continue;
    }
    const TriangleIndices& tri = mesh.triangles[t];
    for (int k = 0; k < 3; ++k) {
      const std::uint32_t a = tri[k];
      const std::uint32_t b = tri[(k + 1) % 3];
      const std::uint32_t lo = std::min(a, b);
      const std::uint32_t hi = std::max(a, b);
      uses.push_back({(std::uint64_t{lo} << 32) | hi, static_cast<std::uint32_t>(t), a < b});
    }
  }
  std::sort(uses.begin(), uses.end(), [](const EdgeUse& x, const EdgeUse& y) {
    return x.key != y.key ? x.key < y.key : x.tri < y.tri;
  });
  return uses;
}

// Per-triangle classification and per-component facts shared by validation and repair.
struct Analysis {
  MeshReport report;
  std::vector<char> bad_index;                       // per triangle
  std::vector<char> non_finite;                      // per triangle: touches a non-finite vertex
  std::vector<char> degenerate;                      // per triangle
  std::vector<char> duplicate;                       // per triangle: a later copy
  std::vector<std::uint32_t> component_of_triangle;  // kNoTriangle for bad-index triangles
  std::vector<char> component_inverted;              // per component id (dense)
};

Analysis analyse(const TriangleMesh& mesh, const MeshValidationOptions& options) {
  Analysis an;
  MeshReport& r = an.report;
  const std::size_t nv = mesh.vertices.size();
  const std::size_t nt = mesh.triangles.size();
  r.vertex_count = nv;
  r.triangle_count = nt;

  std::vector<char> vertex_finite(nv);
  for (std::size_t v = 0; v < nv; ++v) {
    vertex_finite[v] = is_finite(mesh.vertices[v]) ? 1 : 0;
    if (vertex_finite[v]) {
      r.bounds.extend(mesh.vertices[v]);
    } else {
      ++r.non_finite_vertices;
    }
  }
  const double diag2 = r.bounds.isEmpty() ? 0.0 : r.bounds.diagonal().squaredNorm();
  const double degenerate_area2 = options.degenerate_area_rel * diag2;

  an.bad_index.assign(nt, 0);
  an.non_finite.assign(nt, 0);
  an.degenerate.assign(nt, 0);
  an.duplicate.assign(nt, 0);
  std::vector<char> used(nv, 0);
  for (std::size_t t = 0; t < nt; ++t) {
    const TriangleIndices& tri = mesh.triangles[t];
    if (!in_range(tri, nv)) {
      an.bad_index[t] = 1;
      ++r.out_of_range_triangles;
      continue;
    }
    for (std::uint32_t v : tri) {
      used[v] = 1;
    }
    const bool finite = vertex_finite[tri[0]] && vertex_finite[tri[1]] && vertex_finite[tri[2]];
    an.non_finite[t] = finite ? 0 : 1;
    if (repeats_index(tri)) {
      an.degenerate[t] = 1;
    } else if (finite) {
      const double area2 = mesh.face_normal_area2(t).norm();
      an.degenerate[t] = area2 <= degenerate_area2 ? 1 : 0;
      r.surface_area += 0.5 * area2;
      const auto [a, b, c] = mesh.corners(t);
      r.signed_volume += a.dot(b.cross(c)) / 6.0;
    }
    r.degenerate_triangles += an.degenerate[t];
  }
  r.unused_vertices = static_cast<std::size_t>(std::count(used.begin(), used.end(), 0));

  // Duplicates: same vertex set, any order; the first copy is kept, later ones counted.
  {
    std::vector<std::pair<TriangleIndices, std::uint32_t>> sorted;
    sorted.reserve(nt);
    for (std::size_t t = 0; t < nt; ++t) {
      if (an.bad_index[t] || an.degenerate[t]) {  // a degenerate copy is counted once
        continue;
      }
      TriangleIndices key = mesh.triangles[t];
      std::sort(key.begin(), key.end());
      sorted.emplace_back(key, static_cast<std::uint32_t>(t));
    }
    std::sort(sorted.begin(), sorted.end());
    for (std::size_t i = 1; i < sorted.size(); ++i) {
      if (sorted[i].first == sorted[i - 1].first) {
        an.duplicate[sorted[i].second] = 1;
        ++r.duplicate_triangles;
      }
    }
  }

  // Topology uses in-range triangles that are neither degenerate nor duplicates: each defect is
  // reported once under its own name (a duplicate is not also three non-manifold edges), and
  // the edge counts describe the mesh as it is after the default repairs drop those triangles.
  std::vector<char> in_topology(nt, 0);
  UnionFind uf(nv);
  std::vector<char> used_topo(nv, 0);
  std::size_t topo_faces = 0;
  for (std::size_t t = 0; t < nt; ++t) {
    if (an.bad_index[t]) {
      continue;
    }
    const TriangleIndices& tri = mesh.triangles[t];
    uf.unite(tri[0], tri[1]);
    uf.unite(tri[1], tri[2]);
    if (!an.degenerate[t] && !an.duplicate[t]) {
      in_topology[t] = 1;
      ++topo_faces;
      for (std::uint32_t v : tri) {
        used_topo[v] = 1;
      }
    }
  }

  // Dense component ids over used vertices.
  std::vector<std::uint32_t> component_of_root(nv, kNoTriangle);
  std::uint32_t n_components = 0;
  for (std::size_t v = 0; v < nv; ++v) {
    if (used[v]) {
      const std::uint32_t root = uf.find(static_cast<std::uint32_t>(v));
      if (component_of_root[root] == kNoTriangle) {
        component_of_root[root] = n_components++;
      }
    }
  }
  r.components = n_components;
  an.component_of_triangle.assign(nt, kNoTriangle);
  for (std::size_t t = 0; t < nt; ++t) {
    if (!an.bad_index[t]) {
      an.component_of_triangle[t] = component_of_root[uf.find(mesh.triangles[t][0])];
    }
  }

  std::vector<char> component_defective(n_components, 0);
  const std::vector<EdgeUse> uses = collect_edge_uses(mesh, in_topology);
  for (std::size_t i = 0; i < uses.size();) {
    std::size_t j = i;
    while (j < uses.size() && uses[j].key == uses[i].key) {
      ++j;
    }
    const std::size_t faces = j - i;
    ++r.edge_count;
    bool bad = false;
    if (faces == 1) {
      ++r.open_edges;
      bad = true;
    } else if (faces > 2) {
      ++r.non_manifold_edges;
      bad = true;
    } else if (uses[i].forward == uses[i + 1].forward) {
      ++r.inconsistent_edges;
      bad = true;
    } else if (an.non_finite[uses[i].tri] == 0 && an.non_finite[uses[i + 1].tri] == 0 &&
               is_fold(mesh.face_normal_area2(uses[i].tri).normalized(),
                       mesh.face_normal_area2(uses[i + 1].tri).normalized())) {
      ++r.folded_edges;
    }
    if (bad) {
      component_defective[an.component_of_triangle[uses[i].tri]] = 1;
    }
    i = j;
  }
  const auto used_topo_count =
      static_cast<long long>(std::count(used_topo.begin(), used_topo.end(), 1));
  r.euler_characteristic =
      used_topo_count - static_cast<long long>(r.edge_count) + static_cast<long long>(topo_faces);
  r.closed = topo_faces > 0 && r.open_edges == 0 && r.non_manifold_edges == 0 &&
             r.inconsistent_edges == 0 && r.out_of_range_triangles == 0 &&
             r.duplicate_triangles == 0;

  // Inside-out components: closed and consistent, negative volume, and not a cavity (a
  // negative shell whose box lies inside a positive component's box is a hollow's inner wall).
  std::vector<double> volume(n_components, 0.0);
  std::vector<Box3> box(n_components);
  for (std::size_t t = 0; t < nt; ++t) {
    const std::uint32_t c = an.component_of_triangle[t];
    if (c == kNoTriangle || an.non_finite[t]) {
      if (c != kNoTriangle) {
        component_defective[c] = 1;  // volume unknown
      }
      continue;
    }
    const auto [a, b, cc] = mesh.corners(t);
    volume[c] += a.dot(b.cross(cc)) / 6.0;
    box[c].extend(a);
    box[c].extend(b);
    box[c].extend(cc);
  }
  an.component_inverted.assign(n_components, 0);
  for (std::uint32_t c = 0; c < n_components; ++c) {
    if (component_defective[c] || !(volume[c] < 0.0)) {
      continue;
    }
    bool cavity = false;
    for (std::uint32_t o = 0; o < n_components && !cavity; ++o) {
      cavity = o != c && volume[o] > 0.0 && box[o].contains(box[c]) && !box[c].contains(box[o]);
    }
    if (!cavity) {
      an.component_inverted[c] = 1;
      ++r.inverted_components;
    }
  }
  return an;
}

// Keeps triangles where keep[t] is true.
std::size_t filter_triangles(TriangleMesh& mesh, const std::vector<char>& drop) {
  std::size_t out = 0;
  for (std::size_t t = 0; t < mesh.triangles.size(); ++t) {
    if (!drop[t]) {
      mesh.triangles[out++] = mesh.triangles[t];
    }
  }
  const std::size_t removed = mesh.triangles.size() - out;
  mesh.triangles.resize(out);
  return removed;
}

// Flips triangles so neighbours across two-triangle edges agree (breadth-first per component,
// keeping the majority orientation so as few triangles as possible change).
std::size_t orient_consistently(TriangleMesh& mesh) {
  const std::size_t nt = mesh.triangles.size();
  std::vector<char> in_topology(nt, 0);
  for (std::size_t t = 0; t < nt; ++t) {
    in_topology[t] =
        in_range(mesh.triangles[t], mesh.vertices.size()) && !repeats_index(mesh.triangles[t]);
  }
  const std::vector<EdgeUse> uses = collect_edge_uses(mesh, in_topology);
  // Adjacency across manifold edges: neighbour and whether both traverse it the same way.
  std::vector<std::vector<std::pair<std::uint32_t, bool>>> adjacent(nt);
  for (std::size_t i = 0; i < uses.size();) {
    std::size_t j = i;
    while (j < uses.size() && uses[j].key == uses[i].key) {
      ++j;
    }
    if (j - i == 2) {
      const bool same = uses[i].forward == uses[i + 1].forward;
      adjacent[uses[i].tri].emplace_back(uses[i + 1].tri, same);
      adjacent[uses[i + 1].tri].emplace_back(uses[i].tri, same);
    }
    i = j;
  }
  std::vector<signed char> flip(nt, -1);  // -1 unvisited, 0 keep, 1 flip
  std::vector<std::uint32_t> queue;
  std::size_t flipped_total = 0;
  for (std::size_t seed = 0; seed < nt; ++seed) {
    if (!in_topology[seed] || flip[seed] >= 0) {
      continue;
    }
    queue.assign(1, static_cast<std::uint32_t>(seed));
    flip[seed] = 0;
    for (std::size_t q = 0; q < queue.size(); ++q) {
      const std::uint32_t f = queue[q];
      for (const auto& [g, same] : adjacent[f]) {
        if (flip[g] < 0) {
          // Same traversal direction means one of the two must turn.
          flip[g] = static_cast<signed char>(same ? 1 - flip[f] : flip[f]);
          queue.push_back(g);
        }
      }
    }
    const auto flips = static_cast<std::size_t>(
        std::count_if(queue.begin(), queue.end(), [&](std::uint32_t t) { return flip[t] == 1; }));
    const bool invert = 2 * flips > queue.size();
    for (std::uint32_t t : queue) {
      if ((flip[t] == 1) != invert) {
        std::swap(mesh.triangles[t][1], mesh.triangles[t][2]);
        ++flipped_total;
      }
    }
  }
  return flipped_total;
}

std::string plural(std::size_t n, std::string_view what) {
  std::string s = std::to_string(n) + " " + std::string(what);
  if (n != 1) {
    s = what == "vertex" ? std::to_string(n) + " vertices" : s + "s";
  }
  return s;
}

}  // namespace

std::string_view to_string(MeshDefect defect) {
  switch (defect) {
    case MeshDefect::kNonFiniteVertex:
      return "non_finite_vertices";
    case MeshDefect::kOutOfRangeIndex:
      return "out_of_range_triangles";
    case MeshDefect::kDegenerateTriangle:
      return "degenerate_triangles";
    case MeshDefect::kDuplicateTriangle:
      return "duplicate_triangles";
    case MeshDefect::kOpenEdge:
      return "open_edges";
    case MeshDefect::kNonManifoldEdge:
      return "non_manifold_edges";
    case MeshDefect::kInconsistentOrientation:
      return "inconsistent_edges";
    case MeshDefect::kInvertedComponent:
      return "inverted_components";
    case MeshDefect::kUnusedVertex:
      return "unused_vertices";
  }
  return "unknown";
}

std::string_view to_string(DefectAction action) {
  switch (action) {
    case DefectAction::kIgnore:
      return "ignore";
    case DefectAction::kWarn:
      return "warn";
    case DefectAction::kRepair:
      return "repair";
    case DefectAction::kRefuse:
      return "refuse";
  }
  return "unknown";
}

ValidationPolicy ValidationPolicy::strict() {
  ValidationPolicy p;
  p.actions.fill(DefectAction::kRefuse);
  p[MeshDefect::kUnusedVertex] = DefectAction::kRepair;
  return p;
}

ValidationPolicy ValidationPolicy::repair_all() {
  ValidationPolicy p;
  p.actions.fill(DefectAction::kRepair);
  p[MeshDefect::kNonFiniteVertex] = DefectAction::kRefuse;
  p[MeshDefect::kOutOfRangeIndex] = DefectAction::kRefuse;
  return p;
}

ValidationPolicy ValidationPolicy::warn_only() {
  ValidationPolicy p;
  p.actions.fill(DefectAction::kWarn);
  return p;
}

std::size_t MeshReport::count(MeshDefect defect) const {
  switch (defect) {
    case MeshDefect::kNonFiniteVertex:
      return non_finite_vertices;
    case MeshDefect::kOutOfRangeIndex:
      return out_of_range_triangles;
    case MeshDefect::kDegenerateTriangle:
      return degenerate_triangles;
    case MeshDefect::kDuplicateTriangle:
      return duplicate_triangles;
    case MeshDefect::kOpenEdge:
      return open_edges;
    case MeshDefect::kNonManifoldEdge:
      return non_manifold_edges;
    case MeshDefect::kInconsistentOrientation:
      return inconsistent_edges;
    case MeshDefect::kInvertedComponent:
      return inverted_components;
    case MeshDefect::kUnusedVertex:
      return unused_vertices;
  }
  return 0;
}

bool MeshReport::has_defects() const {
  for (std::size_t d = 0; d < kMeshDefectCount; ++d) {
    if (count(static_cast<MeshDefect>(d)) > 0) {
      return true;
    }
  }
  return false;
}

std::string MeshReport::summary() const {
  std::ostringstream out;
  out << plural(triangle_count, "triangle") << ", " << plural(vertex_count, "vertex") << ", "
      << (closed ? "closed" : "not closed") << ", " << plural(components, "component");
  std::string defects;
  for (std::size_t d = 0; d < kMeshDefectCount; ++d) {
    const auto defect = static_cast<MeshDefect>(d);
    if (const std::size_t n = count(defect); n > 0) {
      defects +=
          (defects.empty() ? "" : ", ") + std::string(to_string(defect)) + "=" + std::to_string(n);
    }
  }
  out << "; " << (defects.empty() ? "no defects" : defects);
  if (folded_edges > 0) {
    out << "; " << plural(folded_edges, "folded edge")
        << " (inside/outside unreliable next to them)";
  }
  return out.str();
}

std::string MeshReport::to_json(int indent) const {
  nlohmann::json j;
  j["vertices"] = vertex_count;
  j["triangles"] = triangle_count;
  j["edges"] = edge_count;
  for (std::size_t d = 0; d < kMeshDefectCount; ++d) {
    const auto defect = static_cast<MeshDefect>(d);
    j[std::string(to_string(defect))] = count(defect);
  }
  j["folded_edges"] = folded_edges;
  j["components"] = components;
  j["closed"] = closed;
  j["euler_characteristic"] = euler_characteristic;
  // JSON has no NaN: a non-finite total (possible only with bad input) becomes null.
  j["signed_volume_m3"] = std::isfinite(signed_volume) ? nlohmann::json(signed_volume) : nullptr;
  j["surface_area_m2"] = std::isfinite(surface_area) ? nlohmann::json(surface_area) : nullptr;
  if (bounds.isEmpty()) {
    j["bbox_min_m"] = nullptr;
    j["bbox_max_m"] = nullptr;
  } else {
    j["bbox_min_m"] = {bounds.min().x(), bounds.min().y(), bounds.min().z()};
    j["bbox_max_m"] = {bounds.max().x(), bounds.max().y(), bounds.max().z()};
  }
  j["notes"] = notes;
  return j.dump(indent);
}

bool is_fold(const Vec3& unit_normal_a, const Vec3& unit_normal_b) {
  static const double kCos = std::cos(kFoldAngleDeg * std::numbers::pi / 180.0);
  return unit_normal_a.dot(unit_normal_b) < kCos;
}

MeshReport validate_mesh(const TriangleMesh& mesh, const MeshValidationOptions& options) {
  return analyse(mesh, options).report;
}

bool MeshRepairStats::any() const {
  return dropped_non_finite + dropped_out_of_range + dropped_degenerate + dropped_duplicate +
             reoriented_triangles + flipped_components + removed_vertices >
         0;
}

std::string MeshRepairStats::summary() const {
  std::vector<std::string> parts;
  const auto add = [&parts](std::size_t n, std::string_view text) {
    if (n > 0) {
      parts.push_back(std::string(text) + " " + std::to_string(n));
    }
  };
  add(dropped_out_of_range, "dropped triangles with out-of-range indices:");
  add(dropped_non_finite, "dropped triangles with non-finite vertices:");
  add(dropped_degenerate, "dropped degenerate triangles:");
  add(dropped_duplicate, "dropped duplicate triangles:");
  add(reoriented_triangles, "re-oriented triangles:");
  add(flipped_components, "flipped inside-out components:");
  add(removed_vertices, "removed unused vertices:");
  if (parts.empty()) {
    return "no repairs";
  }
  std::string s = parts.front();
  for (std::size_t i = 1; i < parts.size(); ++i) {
    s += "; " + parts[i];
  }
  return s;
}

void flip_orientation(TriangleMesh& mesh) {
  for (TriangleIndices& t : mesh.triangles) {
    std::swap(t[1], t[2]);
  }
  for (Vec3& n : mesh.vertex_normals) {
    n = -n;
  }
}

MeshRepairStats repair_mesh(TriangleMesh& mesh, const ValidationPolicy& policy,
                            const MeshValidationOptions& options) {
  MeshRepairStats stats;
  const auto repair = [&policy](MeshDefect d) { return policy[d] == DefectAction::kRepair; };
  const bool had_normals = !mesh.vertex_normals.empty();

  // 1. Drop triangles that are unusable or redundant.
  {
    const Analysis an = analyse(mesh, options);
    std::vector<char> drop(mesh.triangles.size(), 0);
    for (std::size_t t = 0; t < mesh.triangles.size(); ++t) {
      if (an.bad_index[t]) {
        if (repair(MeshDefect::kOutOfRangeIndex)) {
          drop[t] = 1;
          ++stats.dropped_out_of_range;
        }
      } else if (an.non_finite[t] && repair(MeshDefect::kNonFiniteVertex)) {
        drop[t] = 1;
        ++stats.dropped_non_finite;
      } else if (an.degenerate[t] && repair(MeshDefect::kDegenerateTriangle)) {
        drop[t] = 1;
        ++stats.dropped_degenerate;
      } else if (an.duplicate[t] && repair(MeshDefect::kDuplicateTriangle)) {
        drop[t] = 1;
        ++stats.dropped_duplicate;
      }
    }
    filter_triangles(mesh, drop);
  }

  // 2. Consistent orientation, then 3. outward orientation per closed component.
  if (repair(MeshDefect::kInconsistentOrientation)) {
    stats.reoriented_triangles = orient_consistently(mesh);
  }
  if (repair(MeshDefect::kInvertedComponent)) {
    const Analysis an = analyse(mesh, options);
    for (std::size_t t = 0; t < mesh.triangles.size(); ++t) {
      const std::uint32_t c = an.component_of_triangle[t];
      if (c != kNoTriangle && an.component_inverted[c]) {
        std::swap(mesh.triangles[t][1], mesh.triangles[t][2]);
      }
    }
    stats.flipped_components = an.report.inverted_components;
  }

  // 4. Remove unused vertices (and non-finite ones no triangle needs any more). Skipped while
  // out-of-range indices remain: renumbering would silently make them point somewhere valid.
  const bool indices_ok =
      std::all_of(mesh.triangles.begin(), mesh.triangles.end(),
                  [&](const TriangleIndices& t) { return in_range(t, mesh.vertices.size()); });
  const bool remove_unused = repair(MeshDefect::kUnusedVertex);
  const bool remove_non_finite = repair(MeshDefect::kNonFiniteVertex);
  if (indices_ok && (remove_unused || remove_non_finite)) {
    const std::size_t nv = mesh.vertices.size();
    std::vector<char> used(nv, 0);
    for (const TriangleIndices& t : mesh.triangles) {
      for (std::uint32_t v : t) {
        used[v] = 1;
      }
    }
    std::vector<std::uint32_t> remap(nv, kNoTriangle);
    std::vector<Vec3> kept;
    kept.reserve(nv);
    for (std::size_t v = 0; v < nv; ++v) {
      const bool drop = !used[v] && (remove_unused || !is_finite(mesh.vertices[v]));
      if (!drop) {
        remap[v] = static_cast<std::uint32_t>(kept.size());
        kept.push_back(mesh.vertices[v]);
      }
    }
    stats.removed_vertices = nv - kept.size();
    if (stats.removed_vertices > 0) {
      for (TriangleIndices& t : mesh.triangles) {
        for (std::uint32_t& v : t) {
          v = remap[v];
        }
      }
      mesh.vertices = std::move(kept);
    }
  }

  if (stats.any() && (had_normals || !mesh.vertex_normals.empty())) {
    if (indices_ok) {
      mesh.compute_vertex_normals();
    } else {
      mesh.vertex_normals.clear();  // cannot compute with bad indices; leave none, not stale
    }
  }
  return stats;
}

}  // namespace hapsim
