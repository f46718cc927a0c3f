#include "hapsim/geometry/polygonizer.h"

#include "hapsim/core/error.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <map>
#include <numbers>
#include <string>
#include <utility>
#include <vector>

namespace hapsim {
namespace {

constexpr double kPi = std::numbers::pi;

// Edge bookkeeping done here, independently of the library: every undirected edge must be used
// by exactly two triangles, once in each direction (closed, manifold, consistently oriented).
struct Topology {
  std::size_t edges = 0;
  std::size_t bad_edges = 0;  // not exactly one use per direction
  std::size_t unused_vertices = 0;
  long euler = 0;  // V − E + F
};

Topology topology(const TriangleMesh& m) {
  std::map<std::pair<std::uint32_t, std::uint32_t>, std::pair<int, int>> uses;
  std::vector<bool> used(m.vertices.size(), false);
  for (const TriangleIndices& t : m.triangles) {
    for (int e = 0; e < 3; ++e) {
      const std::uint32_t a = t[e];
      const std::uint32_t b = t[(e + 1) % 3];
      used.at(a) = true;
      auto& u = uses[{std::min(a, b), std::max(a, b)}];
      (a < b ? u.first : u.second) += 1;
    }
  }
  Topology topo;
  topo.edges = uses.size();
  for (const auto& [edge, u] : uses) {
    if (u.first != 1 || u.second != 1) {
      ++topo.bad_edges;
    }
  }
  for (bool u : used) {
    topo.unused_vertices += u ? 0 : 1;
  }
  topo.euler = static_cast<long>(m.vertices.size()) - static_cast<long>(topo.edges) +
               static_cast<long>(m.triangles.size());
  return topo;
}

void expect_closed(const TriangleMesh& m, long euler) {
  const Topology t = topology(m);
  EXPECT_GT(m.triangle_count(), 0U);
  EXPECT_EQ(t.bad_edges, 0U) << "of " << t.edges << " edges";
  EXPECT_EQ(t.unused_vertices, 0U);
  EXPECT_EQ(t.euler, euler);
  EXPECT_EQ(2 * t.edges, 3 * m.triangle_count());
  EXPECT_GT(m.signed_volume(), 0.0);
}

void expect_on_surface(const CsgSolid& s, const TriangleMesh& m, double tolerance_m) {
  double worst = 0.0;
  for (const Vec3& v : m.vertices) {
    worst = std::max(worst, std::abs(s.distance(v)));
  }
  EXPECT_LE(worst, tolerance_m);
}

TEST(PolygonizerTest, SphereClosedAccurateOutward) {
  const double r = 0.05;
  const double h = 0.005;  // 10 cells per radius
  const CsgSolid ball = CsgSolid::sphere(r);
  PolygonizeOptions opt;
  opt.cell_size_m = h;
  PolygonizeStats stats;
  const TriangleMesh m = polygonize(ball, opt, &stats);
  expect_closed(m, 2);
  EXPECT_DOUBLE_EQ(stats.cell_size_m, h);
  expect_on_surface(ball, m, 1e-6 * r);
  EXPECT_LE(stats.max_vertex_distance_m, 1e-9 * r);
  // Vertices are on the sphere, so every triangle is a chord inside the ball: V ≤ V0. Triangles
  // span at most a cell's body diagonal L = √3·h, a chord of length L sags by at most
  // L²/(8r)·4 (its circumscribed circle has radius ≤ L), so V ≥ V0 − A0·L²/(2r).
  const double v0 = 4.0 / 3.0 * kPi * r * r * r;
  const double a0 = 4.0 * kPi * r * r;
  const double sag = 3.0 * h * h / (2.0 * r);
  EXPECT_LE(m.signed_volume(), v0 * (1 + 1e-9));
  EXPECT_GE(m.signed_volume(), v0 - a0 * sag);
  // Area: chords are shorter than arcs (≤ A0) but marching-tetrahedra facets tilt by up to
  // ~45° from the true normal, which can only add area; bound both by the same sag term and
  // the tilt: A0(1 − 2·sag/r) ≤ A ≤ A0·√2.
  EXPECT_GE(m.surface_area(), a0 * (1 - 2 * sag / r));
  EXPECT_LE(m.surface_area(), a0 * std::sqrt(2.0));
  // Normals point away from the centre (the sphere is star-shaped about it); degenerate
  // (zero-area) triangles have no direction to test.
  std::size_t inward = 0;
  for (std::size_t t = 0; t < m.triangle_count(); ++t) {
    const auto [a, b, c] = m.corners(t);
    if (m.face_normal_area2(t).dot((a + b + c) / 3.0) < 0.0) {
      ++inward;
    }
  }
  EXPECT_EQ(inward, 0U);
  ASSERT_EQ(m.vertex_normals.size(), m.vertices.size());
  for (std::size_t v = 0; v < m.vertices.size(); ++v) {
    EXPECT_NEAR((m.vertex_normals[v] - m.vertices[v] / r).norm(), 0.0, 1e-6);
  }
}

TEST(PolygonizerTest, SphereConvergesWithCellSize) {
  // Halving the cell must shrink the volume error (second order: about 4×).
  const CsgSolid ball = CsgSolid::sphere(1.0);
  const double v0 = 4.0 / 3.0 * kPi;
  double previous = kInf;
  for (double h : {0.2, 0.1, 0.05}) {
    PolygonizeOptions opt;
    opt.cell_size_m = h;
    const double err = v0 - polygonize(ball, opt).signed_volume();
    EXPECT_GT(err, 0.0);
    EXPECT_LT(err, previous / 2.5) << "h = " << h;
    previous = err;
  }
}

TEST(PolygonizerTest, LinearPlacementIsClosedButLessAccurate) {
  const CsgSolid ball = CsgSolid::sphere(1.0);
  PolygonizeOptions opt;
  opt.cell_size_m = 0.1;
  opt.refine_vertices = false;
  opt.gradient_normals = false;
  const TriangleMesh linear = polygonize(ball, opt);
  expect_closed(linear, 2);
  EXPECT_TRUE(linear.vertex_normals.empty());
  double worst = 0.0;
  for (const Vec3& v : linear.vertices) {
    worst = std::max(worst, std::abs(ball.distance(v)));
  }
  EXPECT_GT(worst, 1e-4);  // the interpolated vertices are visibly off the surface
  EXPECT_LT(worst, 0.1);   // but within a cell
}

TEST(PolygonizerTest, TorusHasGenusOne) {
  const CsgSolid torus = CsgSolid::torus(0.04, 0.012)
                             .transformed(Eigen::Translation3d(0.1, -0.2, 0.3) *
                                          Eigen::AngleAxisd(0.7, Vec3(1, 1, 0).normalized()));
  PolygonizeOptions opt;
  opt.cell_size_m = 0.002;
  const TriangleMesh m = polygonize(torus, opt);
  expect_closed(m, 0);
  expect_on_surface(torus, m, 1e-9 * 0.1);
  const double v0 = 2.0 * kPi * kPi * 0.04 * 0.012 * 0.012;
  EXPECT_NEAR(m.signed_volume(), v0, 0.02 * v0);
}

TEST(PolygonizerTest, BoxMinusSphereCavityIsTwoClosedShells) {
  // A cavity: outer cube surface and inner (inward-facing) sphere, both closed: χ = 2 + 2.
  const CsgSolid shell = CsgSolid::block(Vec3(1, 1, 1)) - CsgSolid::sphere(0.6);
  PolygonizeOptions opt;
  opt.cell_size_m = 0.05;
  const TriangleMesh m = polygonize(shell, opt);
  expect_closed(m, 4);
  expect_on_surface(shell, m, 1e-9 * 2);
  // Cube edges and corners are bevelled by about a cell: 12 edges of length 2 lose at most a
  // right triangle of legs h each.
  const double v0 = 8.0 - 4.0 / 3.0 * kPi * 0.6 * 0.6 * 0.6;
  const double h = opt.cell_size_m;
  EXPECT_LE(m.signed_volume(), v0 * (1 + 1e-9));
  EXPECT_GE(m.signed_volume(), v0 - 12 * 2 * h * h / 2 - 4 * kPi * 0.36 * 3 * h * h / (2 * 0.6));
}

TEST(PolygonizerTest, ThroughHoleHasGenusOne) {
  const CsgSolid ring = CsgSolid::block(Vec3(0.02, 0.02, 0.01)) - CsgSolid::cylinder(0.01, 0.02);
  PolygonizeOptions opt;
  opt.cell_size_m = 0.001;
  const TriangleMesh m = polygonize(ring, opt);
  expect_closed(m, 0);
  expect_on_surface(ring, m, 1e-9 * 0.04);
}

TEST(PolygonizerTest, ConeAndUnionTree) {
  const CsgSolid tree = CsgSolid::cone(0.03, 0.05) |
                        CsgSolid::cylinder(0.01, 0.04) |
                        CsgSolid::sphere(0.015).transformed(Iso3(Eigen::Translation3d(0, 0, 0.05)));
  PolygonizeOptions opt;
  opt.max_cells_per_axis = 60;
  PolygonizeStats stats;
  const TriangleMesh m = polygonize(tree, opt, &stats);
  expect_closed(m, 2);
  const Vec3 ext = tree.bounds().sizes();
  EXPECT_NEAR(stats.cell_size_m, ext.maxCoeff() / 60, 1e-15);
  expect_on_surface(tree, m, 1e-9 * ext.maxCoeff());
}

TEST(PolygonizerTest, ResultDoesNotDependOnThreads) {
  const CsgSolid s = CsgSolid::torus(1.0, 0.3) - CsgSolid::block(Vec3(0.5, 2, 2));
  PolygonizeOptions opt;
  opt.cell_size_m = 0.01;  // slabs big enough to be split between threads
  opt.threads = 1;
  const TriangleMesh a = polygonize(s, opt);
  opt.threads = 2;
  const TriangleMesh b = polygonize(s, opt);
  ASSERT_EQ(a.vertices.size(), b.vertices.size());
  ASSERT_EQ(a.triangles, b.triangles);
  EXPECT_EQ(a.vertices, b.vertices);
  expect_closed(a, 4);  // two C-shaped halves, each a topological sphere
}

TEST(PolygonizerTest, ReportsProgress) {
  std::vector<double> fractions;
  PolygonizeOptions opt;
  opt.cell_size_m = 0.05;
  opt.progress = [&](std::string_view label, double f) {
    EXPECT_EQ(label, "polygonize");
    fractions.push_back(f);
  };
  (void)polygonize(CsgSolid::sphere(1.0), opt);
  ASSERT_GE(fractions.size(), 10U);
  for (std::size_t i = 1; i < fractions.size(); ++i) {
    EXPECT_GT(fractions[i], fractions[i - 1]);
  }
  EXPECT_DOUBLE_EQ(fractions.back(), 1.0);
}

void expect_error(const CsgSolid& s, const PolygonizeOptions& opt, const std::string& needle) {
  try {
    (void)polygonize(s, opt);
    ADD_FAILURE() << "expected hapsim::Error mentioning '" << needle << "'";
  } catch (const Error& e) {
    EXPECT_EQ(e.where(), "polygonize");
    EXPECT_NE(std::string(e.what()).find(needle), std::string::npos) << e.what();
  }
}

TEST(PolygonizerTest, BadOptionsAndEmptySolidsAreErrors) {
  const CsgSolid ball = CsgSolid::sphere(1.0);
  PolygonizeOptions opt;
  expect_error(ball, opt, "cell_size_m");  // neither cell size nor resolution
  opt.cell_size_m = -0.1;
  expect_error(ball, opt, "cell_size_m");
  opt.cell_size_m = std::nan("");
  expect_error(ball, opt, "cell_size_m");
  opt.cell_size_m = kInf;
  expect_error(ball, opt, "cell_size_m");
  opt.cell_size_m = 0.0;
  opt.max_cells_per_axis = -5;
  expect_error(ball, opt, "max_cells_per_axis");
  // Enormous resolutions are refused before anything is allocated.
  opt.max_cells_per_axis = 0;
  opt.cell_size_m = 1e-9;
  expect_error(ball, opt, "max_grid_nodes");
  opt.cell_size_m = 0.0;
  opt.max_cells_per_axis = 2'000'000'000;
  expect_error(ball, opt, "max_grid_nodes");
  opt.max_cells_per_axis = 0;
  opt.cell_size_m = 0.1;
  opt.padding_cells = 0;
  expect_error(ball, opt, "padding_cells");
  opt.padding_cells = 2;
  // Empty solids.
  expect_error(CsgSolid(), opt, "empty");
  expect_error(ball - CsgSolid::sphere(2.0), opt, "no grid node lies inside");
  expect_error(ball & ball.transformed(Iso3(Eigen::Translation3d(5, 0, 0))), opt, "empty");
  // Thinner than a cell (the node-free gap between grid nodes).
  expect_error(CsgSolid::block(Vec3(1, 1, 1e-4)).transformed(Iso3(Eigen::Translation3d(0, 0, 0.05))),
               opt, "thinner than the cell size");
}

}  // namespace
}  // namespace hapsim
