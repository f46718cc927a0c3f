#include "hapsim/geometry/polygonizer.h"

#include "hapsim/core/error.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <string>
#include <thread>
#include <vector>

namespace hapsim {
namespace {

constexpr const char* kWhere = "polygonize";
constexpr std::uint32_t kUnset = std::numeric_limits<std::uint32_t>::max();

// Cube corners are numbered by bits (x = 1, y = 2, z = 4). A grid edge starts at a node and goes
// along one of the 7 patterns 1..7 (the cube edges, the Kuhn face diagonals and the main
// diagonal); edge key = (node, pattern − 1).
constexpr int kEdgeDirs = 7;

Vec3 corner_offset(int corner) {
  return {static_cast<double>(corner & 1), static_cast<double>((corner >> 1) & 1),
          static_cast<double>((corner >> 2) & 1)};
}

// A grid edge of the cube, named by its start corner and its pattern.
struct EdgeRef {
  std::uint8_t lo;       // corner at the edge's start (subset of hi's bits)
  std::uint8_t pattern;  // hi ^ lo, 1..7
};
struct TetCase {
  int triangle_count = 0;
  std::array<std::array<EdgeRef, 3>, 2> triangles{};
};

// The 6 Kuhn tetrahedra of the unit cube: for each axis order (a, b, c) the path
// 0 → e_a → e_a + e_b → (1,1,1). Every tet edge joins corners whose bit sets are nested, which
// is what makes the split of neighbouring cubes conforming.
std::array<std::array<int, 4>, 6> kuhn_tets() {
  const int perms[6][3] = {{0, 1, 2}, {0, 2, 1}, {1, 0, 2}, {1, 2, 0}, {2, 0, 1}, {2, 1, 0}};
  std::array<std::array<int, 4>, 6> tets{};
  for (int t = 0; t < 6; ++t) {
    const int a = 1 << perms[t][0];
    const int b = 1 << perms[t][1];
    tets[t] = {0, a, a | b, 7};
  }
  return tets;
}

EdgeRef edge_ref(int c0, int c1) {
  const int lo = std::min(c0, c1);  // nested bit sets: the smaller one is the subset
  const int hi = std::max(c0, c1);
  return {static_cast<std::uint8_t>(lo), static_cast<std::uint8_t>(hi ^ lo)};
}

Vec3 edge_mid(int c0, int c1) {
  return 0.5 * (corner_offset(c0) + corner_offset(c1));
}

// Triangles per (tet, inside mask of its 4 vertices). Orientation is fixed combinatorially,
// from the surface that node values ±1 would give (vertices at edge midpoints, a genuine PL
// level set): normals point from inside nodes to outside nodes. Vertices anywhere strictly
// inside their edges give the same orientation (no triangle of a tet piece can degenerate).
std::array<std::array<TetCase, 16>, 6> build_cases() {
  std::array<std::array<TetCase, 16>, 6> cases{};
  const auto tets = kuhn_tets();
  for (int t = 0; t < 6; ++t) {
    for (int mask = 0; mask < 16; ++mask) {
      std::vector<int> in;
      std::vector<int> out;
      for (int v = 0; v < 4; ++v) {
        ((mask >> v) & 1 ? in : out).push_back(tets[t][v]);
      }
      TetCase& tc = cases[t][mask];
      Vec3 c_in = Vec3::Zero();
      Vec3 c_out = Vec3::Zero();
      for (int c : in) {
        c_in += corner_offset(c) / static_cast<double>(in.size());
      }
      for (int c : out) {
        c_out += corner_offset(c) / static_cast<double>(out.size());
      }
      const Vec3 outward = c_out - c_in;
      std::vector<std::array<int, 2>> poly;  // polygon as edges (corner pairs), in cycle order
      if (in.size() == 1 || out.size() == 1) {
        const int apex = in.size() == 1 ? in[0] : out[0];
        const std::vector<int>& rest = in.size() == 1 ? out : in;
        for (int c : rest) {
          poly.push_back({apex, c});
        }
      } else if (in.size() == 2) {
        poly = {{in[0], out[0]}, {in[0], out[1]}, {in[1], out[1]}, {in[1], out[0]}};
      } else {
        continue;  // all inside or all outside
      }
      std::vector<Vec3> pts;
      for (const auto& e : poly) {
        pts.push_back(edge_mid(e[0], e[1]));
      }
      const Vec3 n = poly.size() == 3 ? Vec3((pts[1] - pts[0]).cross(pts[2] - pts[0]))
                                      : Vec3((pts[2] - pts[0]).cross(pts[3] - pts[1]));
      if (n.dot(outward) < 0.0) {
        std::reverse(poly.begin(), poly.end());
      }
      const auto ref = [&](int i) { return edge_ref(poly[i][0], poly[i][1]); };
      tc.triangles[0] = {ref(0), ref(1), ref(2)};
      tc.triangle_count = 1;
      if (poly.size() == 4) {
        tc.triangles[1] = {ref(0), ref(2), ref(3)};
        tc.triangle_count = 2;
      }
    }
  }
  return cases;
}

const std::array<std::array<TetCase, 16>, 6>& tet_cases() {
  static const auto cases = build_cases();
  return cases;
}

struct Grid {
  Vec3 origin;
  double h = 0.0;
  int nx = 0;
  int ny = 0;
  int nz = 0;
  [[nodiscard]] Vec3 node(int i, int j, int k) const {
    return origin +
           h * Vec3(static_cast<double>(i), static_cast<double>(j), static_cast<double>(k));
  }
};

Grid make_grid(const DistanceField& solid, const PolygonizeOptions& options) {
  const Box3 box = solid.bounds;
  if (box.isEmpty()) {
    throw Error(kWhere, "the solid's bounds are empty (e.g. an intersection of disjoint solids)");
  }
  if (!box.min().allFinite() || !box.max().allFinite()) {
    throw Error(kWhere, "the solid's bounds are not finite");
  }
  const Vec3 extent = box.sizes();
  const double longest = extent.maxCoeff();
  const double cell = options.cell_size_m;
  if (std::isnan(cell) || cell < 0.0 || std::isinf(cell)) {
    throw Error(kWhere, "cell_size_m must be finite and > 0, got " + std::to_string(cell));
  }
  if (options.max_cells_per_axis < 0) {
    throw Error(kWhere, "max_cells_per_axis must be > 0 (or 0 for unset), got " +
                            std::to_string(options.max_cells_per_axis));
  }
  if (cell == 0.0 && options.max_cells_per_axis == 0) {
    throw Error(kWhere, "set cell_size_m (> 0) or max_cells_per_axis (> 0)");
  }
  if (options.padding_cells < 1) {
    throw Error(kWhere, "padding_cells must be >= 1, got " + std::to_string(options.padding_cells));
  }
  double h = cell;
  if (options.max_cells_per_axis > 0) {
    h = std::max(h, longest / options.max_cells_per_axis);
  }
  if (!(h > 0.0)) {
    throw Error(kWhere, "the cell size resolves to zero (degenerate bounds?)");
  }
  Grid g;
  g.h = h;
  std::array<double, 3> n{};
  double total = 1.0;
  for (int a = 0; a < 3; ++a) {
    n[a] = std::ceil(extent[a] / h) + 1.0 + 2.0 * options.padding_cells;
    total *= n[a];
  }
  if (!(total <= static_cast<double>(options.max_grid_nodes))) {
    throw Error(kWhere, "the grid would have " + std::to_string(total) + " nodes (cell " +
                            std::to_string(h) + " m over bounds " + std::to_string(extent.x()) +
                            " x " + std::to_string(extent.y()) + " x " +
                            std::to_string(extent.z()) + " m), more than max_grid_nodes = " +
                            std::to_string(options.max_grid_nodes) + "; use a larger cell_size_m");
  }
  g.nx = static_cast<int>(n[0]);
  g.ny = static_cast<int>(n[1]);
  g.nz = static_cast<int>(n[2]);
  // Centre the grid on the bounds so the padding is equal on both sides.
  g.origin = box.center() - 0.5 * h * Vec3(n[0] - 1.0, n[1] - 1.0, n[2] - 1.0);
  return g;
}

// Evaluates the distance at every node of slab k; border nodes are clamped to "outside" so the
// mesh is closed even if bounds() were ever too tight.
void evaluate_slab(const DistanceField& solid, const Grid& g, int k, int threads,
                   std::vector<double>* values) {
  const auto rows = [&](int j0, int j1) {
    for (int j = j0; j < j1; ++j) {
      for (int i = 0; i < g.nx; ++i) {
        double d = solid.distance(g.node(i, j, k));
        if (i == 0 || j == 0 || k == 0 || i == g.nx - 1 || j == g.ny - 1 || k == g.nz - 1) {
          d = std::max(d, 0.0);
        }
        (*values)[static_cast<std::size_t>(j) * g.nx + i] = d;
      }
    }
  };
  // Threads only pay off for big slabs (spawning costs tens of microseconds).
  const int workers = std::min(threads, std::max(1, g.nx * g.ny / 4096));
  if (workers <= 1) {
    rows(0, g.ny);
  } else {
    std::vector<std::thread> pool;
    for (int w = 1; w < workers; ++w) {
      pool.emplace_back(rows, g.ny * w / workers, g.ny * (w + 1) / workers);
    }
    rows(0, g.ny / workers);
    for (auto& th : pool) {
      th.join();
    }
  }
  for (double d : *values) {
    if (std::isnan(d)) {
      throw Error(kWhere, "the signed distance is NaN at a grid node of slab " + std::to_string(k));
    }
  }
}

struct Refined {
  Vec3 p;
  Vec3 gradient;
  double distance;
};

// Finds the zero crossing on the segment p_in (d_in < 0) → p_out (d_out ≥ 0): Newton along the
// segment, safeguarded by a shrinking bracket (bisection when Newton leaves it). The result
// stays on the segment, which is what keeps the triangulation fold-free.
Refined refine_on_edge(const DistanceField& solid, const Vec3& p_in, double d_in, const Vec3& p_out,
                       double d_out, double tolerance_m, std::size_t* evaluations) {
  const Vec3 D = p_out - p_in;
  double lo = 0.0;
  double hi = 1.0;
  double t = d_in / (d_in - d_out);
  Refined best{p_in + t * D, Vec3::Zero(), kInf};
  for (int it = 0; it < 64; ++it) {
    const Vec3 p = p_in + t * D;
    const SdfSample s = solid.evaluate(p);
    ++*evaluations;
    if (std::abs(s.distance_m) < std::abs(best.distance) || it == 0) {
      best = {p, s.gradient, s.distance_m};
    }
    if (std::abs(s.distance_m) <= tolerance_m) {
      break;
    }
    if (s.distance_m < 0.0) {
      lo = t;
    } else {
      hi = t;
    }
    if (hi - lo <= 1e-14) {
      break;
    }
    const double slope = s.gradient.dot(D);
    double next = slope > 0.0 ? t - s.distance_m / slope : -1.0;
    if (!(next > lo && next < hi)) {
      next = 0.5 * (lo + hi);
    }
    t = next;
  }
  return best;
}

}  // namespace

TriangleMesh polygonize(const CsgSolid& solid, const PolygonizeOptions& options,
                        PolygonizeStats* stats) {
  if (solid.is_empty()) {
    throw Error(kWhere, "the solid is empty (no primitive); nothing to polygonise");
  }
  DistanceField field;
  field.evaluate = [&solid](const Vec3& p) { return solid.evaluate(p); };
  field.distance = [&solid](const Vec3& p) { return solid.distance(p); };
  field.bounds = solid.bounds();
  return polygonize(field, options, stats);
}

TriangleMesh polygonize(const DistanceField& solid, const PolygonizeOptions& options,
                        PolygonizeStats* stats) {
  if (!solid.evaluate || !solid.distance) {
    throw Error(kWhere, "the distance field has no evaluation function");
  }
  const Grid g = make_grid(solid, options);
  const int threads = options.threads > 0
                          ? options.threads
                          : std::max(1, static_cast<int>(std::thread::hardware_concurrency()));
  const auto& cases = tet_cases();
  const auto tets = kuhn_tets();
  const std::size_t nxy = static_cast<std::size_t>(g.nx) * g.ny;
  const double scale = std::max(solid.bounds.sizes().maxCoeff(), g.h);
  const double tolerance_m = 1e-10 * scale;

  PolygonizeStats st;
  st.cell_size_m = g.h;
  st.grid_nodes = {g.nx, g.ny, g.nz};
  st.sdf_evaluations = nxy * static_cast<std::size_t>(g.nz);

  TriangleMesh mesh;
  // Two slabs of node values and of edge → vertex ids (slab k and k+1).
  std::array<std::vector<double>, 2> values{std::vector<double>(nxy), std::vector<double>(nxy)};
  std::array<std::vector<std::uint32_t>, 2> ids{
      std::vector<std::uint32_t>(nxy * kEdgeDirs, kUnset),
      std::vector<std::uint32_t>(nxy * kEdgeDirs, kUnset)};
  evaluate_slab(solid, g, 0, threads, &values[0]);

  const auto vertex_on_edge = [&](int i, int j, int k, const EdgeRef& e) -> std::uint32_t {
    const int ox = e.lo & 1;
    const int oy = (e.lo >> 1) & 1;
    const int oz = (e.lo >> 2) & 1;
    const std::size_t node_a = static_cast<std::size_t>(j + oy) * g.nx + (i + ox);
    std::uint32_t& id = ids[oz][node_a * kEdgeDirs + (e.pattern - 1)];
    if (id != kUnset) {
      return id;
    }
    const int px = e.pattern & 1;
    const int py = (e.pattern >> 1) & 1;
    const int pz = (e.pattern >> 2) & 1;
    const std::size_t node_b = static_cast<std::size_t>(j + oy + py) * g.nx + (i + ox + px);
    const double da = values[oz][node_a];
    const double db = values[oz + pz][node_b];
    const Vec3 pa = g.node(i + ox, j + oy, k + oz);
    const Vec3 pb = g.node(i + ox + px, j + oy + py, k + oz + pz);
    const bool a_inside = da < 0.0;
    const Vec3& p_in = a_inside ? pa : pb;
    const Vec3& p_out = a_inside ? pb : pa;
    const double d_in = a_inside ? da : db;
    const double d_out = a_inside ? db : da;
    Refined r;
    if (options.refine_vertices) {
      r = refine_on_edge(solid, p_in, d_in, p_out, d_out, tolerance_m, &st.sdf_evaluations);
    } else {
      r.p = p_in + (d_in / (d_in - d_out)) * (p_out - p_in);
      const SdfSample s = options.gradient_normals ? solid.evaluate(r.p) : SdfSample{};
      st.sdf_evaluations += options.gradient_normals ? 1 : 0;
      r.gradient = s.gradient;
      r.distance = s.distance_m;
    }
    if (mesh.vertices.size() >= kUnset - 1) {
      throw Error(kWhere, "too many vertices for 32-bit indices; use a larger cell_size_m");
    }
    id = static_cast<std::uint32_t>(mesh.vertices.size());
    mesh.vertices.push_back(r.p);
    if (options.gradient_normals) {
      mesh.vertex_normals.push_back(r.gradient);
    }
    if (options.refine_vertices) {
      st.max_vertex_distance_m = std::max(st.max_vertex_distance_m, std::abs(r.distance));
    }
    return id;
  };

  double last_reported = -1.0;
  for (int k = 0; k + 1 < g.nz; ++k) {
    evaluate_slab(solid, g, k + 1, threads, &values[1]);
    for (int j = 0; j + 1 < g.ny; ++j) {
      for (int i = 0; i + 1 < g.nx; ++i) {
        std::array<double, 8> c{};
        int inside = 0;
        for (int corner = 0; corner < 8; ++corner) {
          const int cz = (corner >> 2) & 1;
          const std::size_t idx =
              static_cast<std::size_t>(j + ((corner >> 1) & 1)) * g.nx + (i + (corner & 1));
          c[corner] = values[cz][idx];
          inside |= (c[corner] < 0.0 ? 1 : 0) << corner;
        }
        if (inside == 0 || inside == 0xff) {
          continue;
        }
        for (int t = 0; t < 6; ++t) {
          int mask = 0;
          for (int v = 0; v < 4; ++v) {
            mask |= ((inside >> tets[t][v]) & 1) << v;
          }
          const TetCase& tc = cases[t][mask];
          for (int n = 0; n < tc.triangle_count; ++n) {
            TriangleIndices tri{};
            for (int v = 0; v < 3; ++v) {
              tri[v] = vertex_on_edge(i, j, k, tc.triangles[n][v]);
            }
            mesh.triangles.push_back(tri);
          }
        }
      }
    }
    // Slab k+1 becomes slab k: its in-plane edge ids carry over; its out-of-plane ids were never
    // created (they belong to the next layer) and are unset already.
    std::swap(values[0], values[1]);
    std::swap(ids[0], ids[1]);
    std::fill(ids[1].begin(), ids[1].end(), kUnset);
    const double fraction = static_cast<double>(k + 1) / (g.nz - 1);
    if (fraction - last_reported >= 0.01 || k + 2 == g.nz) {
      report_progress(options.progress, "polygonize", fraction);
      last_reported = fraction;
    }
  }

  if (mesh.triangles.empty()) {
    throw Error(kWhere, "no grid node lies inside the solid (cell " + std::to_string(g.h) +
                            " m): it is empty (e.g. a difference that removes everything) or "
                            "thinner than the cell size everywhere");
  }
  const double degenerate_area2 = 1e-20 * g.h * g.h;
  for (std::size_t t = 0; t < mesh.triangles.size(); ++t) {
    if (mesh.face_normal_area2(t).norm() <= degenerate_area2) {
      ++st.degenerate_triangles;
    }
  }
  if (stats != nullptr) {
    *stats = st;
  }
  return mesh;
}

}  // namespace hapsim
