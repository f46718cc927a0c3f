#include "hapsim/collision/mesh_bvh.h"

#include "hapsim/geometry/procedural.h"

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <random>

namespace hapsim {
namespace {

struct Brute {
  double distance = kInf;
  std::uint32_t triangle = kNoTriangle;
  Vec3 point = Vec3::Zero();
};

Brute brute_force(const TriangleMesh& mesh, const Vec3& p) {
  Brute best;
  double best_d2 = kInf;
  for (std::uint32_t t = 0; t < mesh.triangles.size(); ++t) {
    const auto [a, b, c] = mesh.corners(t);
    const TriangleClosest got = closest_point_on_triangle(p, a, b, c);
    if (got.distance_sq < best_d2) {
      best_d2 = got.distance_sq;
      best = {std::sqrt(got.distance_sq), t, got.point};
    }
  }
  return best;
}

// Generalised winding number (Van Oosterom & Strackee solid angles): 1 inside a closed,
// outward mesh, 0 outside; independent of the pseudo-normal logic under test.
double winding_number(const TriangleMesh& mesh, const Vec3& p) {
  double sum = 0.0;
  for (std::size_t t = 0; t < mesh.triangles.size(); ++t) {
    const auto [a0, b0, c0] = mesh.corners(t);
    const Vec3 a = a0 - p;
    const Vec3 b = b0 - p;
    const Vec3 c = c0 - p;
    const double la = a.norm();
    const double lb = b.norm();
    const double lc = c.norm();
    const double num = a.dot(b.cross(c));
    const double den = la * lb * lc + a.dot(b) * lc + b.dot(c) * la + c.dot(a) * lb;
    sum += 2.0 * std::atan2(num, den);
  }
  return sum / (4.0 * std::numbers::pi);
}

Vec3 random_in_box(std::mt19937_64& rng, const Box3& box, double grow) {
  std::uniform_real_distribution<double> u(0.0, 1.0);
  const Vec3 lo = box.min() - grow * box.sizes();
  const Vec3 size = (1.0 + 2.0 * grow) * box.sizes();
  return lo + size.cwiseProduct(Vec3(u(rng), u(rng), u(rng)));
}

// A point near the surface: a random point of a random triangle pushed along a random direction.
Vec3 random_near_surface(std::mt19937_64& rng, const TriangleMesh& mesh, double spread) {
  std::uniform_int_distribution<std::size_t> pick(0, mesh.triangles.size() - 1);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  std::normal_distribution<double> g(0.0, spread);
  const auto [a, b, c] = mesh.corners(pick(rng));
  double s = u(rng);
  double t = u(rng);
  if (s + t > 1.0) {
    s = 1.0 - s;
    t = 1.0 - t;
  }
  return a + s * (b - a) + t * (c - a) + Vec3(g(rng), g(rng), g(rng));
}

TriangleMesh make_octahedron(double r) {
  TriangleMesh mesh;
  mesh.vertices = {Vec3(r, 0, 0),  Vec3(-r, 0, 0), Vec3(0, r, 0),
                   Vec3(0, -r, 0), Vec3(0, 0, r),  Vec3(0, 0, -r)};
  // Outward (counter-clockwise seen from outside) faces, one per octant.
  for (int sx = 0; sx < 2; ++sx) {
    for (int sy = 0; sy < 2; ++sy) {
      for (int sz = 0; sz < 2; ++sz) {
        const std::uint32_t x = sx == 0 ? 0u : 1u;
        const std::uint32_t y = sy == 0 ? 2u : 3u;
        const std::uint32_t z = sz == 0 ? 4u : 5u;
        const bool flip = (sx + sy + sz) % 2 == 1;
        mesh.triangles.push_back(flip ? TriangleIndices{x, z, y} : TriangleIndices{x, y, z});
      }
    }
  }
  return mesh;
}

void expect_matches_brute_force(const MeshBvh& bvh, const TriangleMesh& mesh, const Vec3& p) {
  const Brute want = brute_force(mesh, p);
  const SurfacePoint got = bvh.closest_point(p);
  ASSERT_TRUE(got.found());
  const double tol = 1e-12 * (want.distance + mesh.bounds().diagonal().norm());
  EXPECT_NEAR(std::abs(got.signed_distance), want.distance, tol) << p.transpose();
  EXPECT_NEAR((p - got.point).norm(), want.distance, tol) << p.transpose();
  if (got.triangle == want.triangle) {
    EXPECT_LT((got.point - want.point).norm(), tol) << p.transpose();
  }
}

TEST(MeshBvh, BoxMatchesAnalyticDistanceSignAndNormal) {
  const Vec3 half(0.01, 0.02, 0.03);
  const TriangleMesh box = make_box(half);
  const MeshBvh bvh(box);
  std::mt19937_64 rng(1);
  int inside = 0;
  for (int i = 0; i < 3000; ++i) {
    const Vec3 p = random_in_box(rng, box.bounds(), 0.5);
    const Vec3 q = p.cwiseAbs() - half;
    const double want = q.maxCoeff() > 0.0 ? q.cwiseMax(0.0).norm() : q.maxCoeff();
    const SurfacePoint got = bvh.closest_point(p);
    EXPECT_NEAR(got.signed_distance, want, 1e-15) << p.transpose();
    EXPECT_NEAR((got.point - p).norm(), std::abs(want), 1e-15);
    if (std::abs(want) > 1e-9) {
      EXPECT_NEAR(got.normal.norm(), 1.0, 1e-12);
      EXPECT_GT(got.normal.dot(p - got.point) * want, 0.0) << p.transpose();
    }
    inside += want < 0.0 ? 1 : 0;
  }
  EXPECT_GT(inside, 200);
  // Straight above a face centre the normal is the face normal.
  const SurfacePoint top = bvh.closest_point(Vec3(0.001, 0.002, 0.05));
  EXPECT_LT((top.normal - Vec3::UnitZ()).norm(), 1e-12);
  EXPECT_NEAR(top.signed_distance, 0.02, 1e-15);
}

// A point that is not finite, or so far out (> 1e15 m) that a double cannot tell the body's near
// face from its far one, has no closest point; a far point within that range is still answered
// right. A query at 1e308 m once crashed the traversal (hapsim polygonize --cell-m 1e308), a NaN
// one the Python interpreter; at 1e19 m the far face won a tie and the sign said "inside".
TEST(MeshBvh, NonFiniteAndAbsurdlyFarPointsHaveNoClosestPoint) {
  const TriangleMesh box = make_box(Vec3(0.01, 0.02, 0.03));
  const MeshBvh bvh(box);
  QueryHint hint;
  for (const double bad : {std::nan(""), kInf, -kInf, 1e19, -1e308}) {
    EXPECT_FALSE(bvh.closest_point(Vec3(0.0, bad, 0.0), &hint).found()) << bad;
  }
  const SurfacePoint far = bvh.closest_point(Vec3(0.0, 0.0, 1e6));
  ASSERT_TRUE(far.found());
  EXPECT_NEAR(far.signed_distance, 1e6 - 0.03, 1e-9);
  EXPECT_NEAR(far.point.z(), 0.03, 1e-12);
}

TEST(MeshBvh, SheetMatchesDistanceToTheRectangle) {
  const double size = 0.2;
  const TriangleMesh sheet = make_sheet(16, size);
  const MeshBvh bvh(sheet);
  std::mt19937_64 rng(2);
  std::uniform_real_distribution<double> u(-0.3, 0.3);
  for (int i = 0; i < 3000; ++i) {
    const Vec3 p(u(rng), u(rng), u(rng));
    const double dx = std::max(std::abs(p.x()) - 0.5 * size, 0.0);
    const double dy = std::max(std::abs(p.y()) - 0.5 * size, 0.0);
    const double want = std::sqrt(dx * dx + dy * dy + p.z() * p.z());
    const SurfacePoint got = bvh.closest_point(p);
    EXPECT_NEAR(std::abs(got.signed_distance), want, 1e-15) << p.transpose();
    EXPECT_NEAR(got.point.z(), 0.0, 1e-15);
    if (dx == 0.0 && dy == 0.0 && std::abs(p.z()) > 1e-12) {
      EXPECT_EQ(got.inside(), p.z() < 0.0);  // a sheet's sign is the side it is seen from
      EXPECT_NEAR(got.point.x(), p.x(), 1e-15);
      EXPECT_NEAR(got.point.y(), p.y(), 1e-15);
    }
  }
}

TEST(MeshBvh, SingleTriangleFeatures) {
  TriangleMesh tri;
  tri.vertices = {Vec3(0, 0, 0), Vec3(1, 0, 0), Vec3(0, 1, 0)};
  tri.triangles = {{0, 1, 2}};
  const MeshBvh bvh(tri);
  EXPECT_EQ(bvh.stats().leaves, 1u);
  struct Case {
    Vec3 p;
    Vec3 point;
  };
  const Case cases[] = {
      {Vec3(0.2, 0.3, 2.0), Vec3(0.2, 0.3, 0)}, {Vec3(0.2, 0.3, -2.0), Vec3(0.2, 0.3, 0)},
      {Vec3(-1, -2, 0.5), Vec3(0, 0, 0)},       {Vec3(3, 0.5, 0), Vec3(1, 0, 0)},
      {Vec3(1, 1, 0), Vec3(0.5, 0.5, 0)},       {Vec3(0.5, -3, 4), Vec3(0.5, 0, 0)}};
  for (const Case& cs : cases) {
    const SurfacePoint got = bvh.closest_point(cs.p);
    EXPECT_EQ(got.triangle, 0u);
    EXPECT_LT((got.point - cs.point).norm(), 1e-15) << cs.p.transpose();
    EXPECT_NEAR(std::abs(got.signed_distance), (cs.p - cs.point).norm(), 1e-15);
  }
  EXPECT_TRUE(bvh.closest_point(Vec3(0.2, 0.3, -2.0)).inside());
  EXPECT_FALSE(bvh.closest_point(Vec3(0.2, 0.3, 2.0)).inside());
}

TEST(MeshBvh, OctahedronMatchesPlaneDistances) {
  const TriangleMesh oct = make_octahedron(0.04);
  ASSERT_GT(oct.signed_volume(), 0.0);
  const MeshBvh bvh(oct);
  std::mt19937_64 rng(3);
  std::uniform_real_distribution<double> u(-0.04, 0.04);
  std::uniform_real_distribution<double> u01(0.0, 1.0);
  const double inv_sqrt3 = 1.0 / std::sqrt(3.0);
  for (int i = 0; i < 2000; ++i) {
    // Inside a convex body the nearest face is the nearest plane.
    const Vec3 p(u(rng), u(rng), u(rng));
    const double l1 = p.cwiseAbs().sum();
    if (l1 >= 0.04) {
      continue;
    }
    const double want = -(0.04 - l1) * inv_sqrt3;
    EXPECT_NEAR(bvh.closest_point(p).signed_distance, want, 1e-15) << p.transpose();
  }
  for (int i = 0; i < 2000; ++i) {
    // Outside, straight off a face: the foot point is the closest point.
    const Vec3 s(u(rng) < 0 ? -1 : 1, u(rng) < 0 ? -1 : 1, u(rng) < 0 ? -1 : 1);
    double a = u01(rng);
    double b = u01(rng);
    if (a + b > 1.0) {
      a = 1.0 - a;
      b = 1.0 - b;
    }
    const Vec3 foot = 0.04 * Vec3(a * s.x(), b * s.y(), (1.0 - a - b) * s.z());
    const double t = 0.05 * u01(rng) + 1e-6;
    const Vec3 p = foot + t * inv_sqrt3 * s;
    const SurfacePoint got = bvh.closest_point(p);
    EXPECT_NEAR(got.signed_distance, t, 1e-15) << p.transpose();
    EXPECT_LT((got.point - foot).norm(), 1e-15);
    EXPECT_LT((got.normal - inv_sqrt3 * s).norm(), 1e-9);
  }
}

TEST(MeshBvh, UvSphereWithinTessellationError) {
  const double radius = 0.05;
  const int segments = 64;
  const int rings = 32;
  const TriangleMesh sphere = make_uv_sphere(radius, segments, rings);
  const MeshBvh bvh(sphere);
  // Vertices lie on the sphere and the mesh is inscribed: surface radii lie in [R - e, R].
  const double step = std::max(2.0 * std::numbers::pi / segments, std::numbers::pi / rings);
  const double e = radius * (1.0 - std::cos(step));
  std::mt19937_64 rng(4);
  std::uniform_real_distribution<double> u(-2.0 * radius, 2.0 * radius);
  int checked = 0;
  for (int i = 0; i < 3000; ++i) {
    const Vec3 p(u(rng), u(rng), u(rng));
    const double rho = p.norm();
    if (rho > radius - e && rho < radius + 1e-9) {
      continue;  // inside the tessellation band: sign is not decided analytically
    }
    const SurfacePoint got = bvh.closest_point(p);
    if (rho > radius) {
      EXPECT_GE(got.signed_distance, rho - radius - 1e-15);
      EXPECT_LE(got.signed_distance, rho - radius + e + 1e-15);
    } else {
      EXPECT_LE(got.signed_distance, -(radius - e - rho) + 1e-15);
      EXPECT_GE(got.signed_distance, -(radius - rho) - 1e-15);
    }
    ++checked;
  }
  EXPECT_GT(checked, 2000);
}

TEST(MeshBvh, SignMatchesWindingNumberOnClosedMeshes) {
  for (const TriangleMesh& mesh : {make_box(Vec3(0.01, 0.02, 0.03)), make_bumpy_sphere(3000)}) {
    const MeshBvh bvh(mesh);
    std::mt19937_64 rng(5);
    int inside = 0;
    int outside = 0;
    for (int i = 0; i < 1500; ++i) {
      const Vec3 p = i % 2 == 0 ? random_in_box(rng, mesh.bounds(), 0.2)
                                : random_near_surface(rng, mesh, 1e-3);
      const SurfacePoint got = bvh.closest_point(p);
      if (std::abs(got.signed_distance) < 1e-7) {
        continue;  // on the surface, the winding number is ambiguous
      }
      const bool want_inside = winding_number(mesh, p) > 0.5;
      EXPECT_EQ(got.inside(), want_inside) << p.transpose() << " d=" << got.signed_distance;
      (want_inside ? inside : outside) += 1;
    }
    EXPECT_GT(inside, 200);
    EXPECT_GT(outside, 200);
  }
}

TEST(MeshBvh, MatchesBruteForceOnBumpySphereAndSheet) {
  for (const TriangleMesh& mesh : {make_bumpy_sphere(5000), make_sheet(40, 0.1)}) {
    const MeshBvh bvh(mesh);
    std::mt19937_64 rng(6);
    for (int i = 0; i < 1000; ++i) {
      const Vec3 p = i % 2 == 0 ? random_in_box(rng, mesh.bounds(), 1.0)
                                : random_near_surface(rng, mesh, 2e-3);
      expect_matches_brute_force(bvh, mesh, p);
    }
  }
}

TEST(MeshBvh, HintNeverChangesTheAnswerOnlyTheWork) {
  const TriangleMesh mesh = make_bumpy_sphere(20000);
  const MeshBvh bvh(mesh);
  std::mt19937_64 rng(7);
  std::uniform_int_distribution<std::uint32_t> pick(
      0, static_cast<std::uint32_t>(mesh.triangles.size() - 1));
  for (int i = 0; i < 2000; ++i) {
    const Vec3 p = random_in_box(rng, mesh.bounds(), 0.3);
    const SurfacePoint plain = bvh.closest_point(p);
    QueryHint hint{i % 7 == 0 ? kNoTriangle : (i % 7 == 1 ? 4000000000u : pick(rng))};
    const SurfacePoint hinted = bvh.closest_point(p, &hint);
    EXPECT_DOUBLE_EQ(hinted.signed_distance, plain.signed_distance) << p.transpose();
    EXPECT_EQ(hint.triangle, hinted.triangle);  // the hint is updated with the answer
  }
  // A smooth trajectory at ~0.05 mm steps that dives deep inside and comes out again: there
  // the nearest-first descent alone finds a poor first bound, last cycle's triangle a tight one.
  QueryHint hint;
  QueryCounters with_hint;
  QueryCounters without_hint;
  for (int i = 0; i < 4000; ++i) {
    const double t = i * 1e-3;
    const double theta = 1.2 + 0.3 * std::sin(t);
    const double phi = 0.4 + t;
    const Vec3 dir(std::sin(theta) * std::cos(phi), std::sin(theta) * std::sin(phi),
                   std::cos(theta));
    const Vec3 p = dir * (0.05 + 0.025 * std::sin(1.5 * t));
    const SurfacePoint a = bvh.closest_point_counted(p, &hint, &with_hint);
    const SurfacePoint b = bvh.closest_point_counted(p, nullptr, &without_hint);
    EXPECT_DOUBLE_EQ(a.signed_distance, b.signed_distance);
  }
  EXPECT_LT(with_hint.nodes_visited, without_hint.nodes_visited);
  EXPECT_LT(with_hint.triangles_tested, without_hint.triangles_tested * 9 / 10);
}

TEST(MeshBvh, ContactWithinIsTrueIffDistanceAtMostRadius) {
  const TriangleMesh mesh = make_bumpy_sphere(8000);
  const MeshBvh bvh(mesh);
  std::mt19937_64 rng(8);
  std::uniform_real_distribution<double> ur(0.0, 0.01);
  int hits = 0;
  for (int i = 0; i < 3000; ++i) {
    const Vec3 p = random_near_surface(rng, mesh, 4e-3);
    const double r = ur(rng);
    const SurfacePoint exact = bvh.closest_point(p);
    SurfacePoint out;
    QueryHint hint;
    const bool hit = bvh.contact_within(p, r, &out, i % 2 == 0 ? &hint : nullptr);
    EXPECT_EQ(hit, std::abs(exact.signed_distance) <= r) << p.transpose() << " r=" << r;
    if (hit) {
      EXPECT_DOUBLE_EQ(out.signed_distance, exact.signed_distance);
      ++hits;
    }
  }
  EXPECT_GT(hits, 300);
  EXPECT_LT(hits, 2700);
  // Exactly at the radius counts as contact.
  const Vec3 p(0.0, 0.0, 0.2);
  const double d = std::abs(bvh.closest_point(p).signed_distance);
  EXPECT_TRUE(bvh.contact_within(p, d, nullptr));
  EXPECT_FALSE(bvh.contact_within(p, std::nextafter(d, 0.0), nullptr));
}

TEST(MeshBvh, ContactWithinExitsEarlyWhenFar) {
  const TriangleMesh mesh = make_bumpy_sphere(100000);
  const MeshBvh bvh(mesh);
  QueryCounters far;
  SurfacePoint out;
  EXPECT_FALSE(bvh.contact_within_counted(Vec3(0.3, 0.1, 0.0), 0.01, &out, nullptr, &far));
  EXPECT_LE(far.nodes_visited, 1u);  // only the root's child boxes are measured
  EXPECT_EQ(far.triangles_tested, 0u);
  // Near the surface, a small radius still explores only a small part of the tree.
  QueryCounters near;
  const Vec3 p = 1.05 * mesh.vertices[mesh.vertices.size() / 2];
  bvh.contact_within_counted(p, 1e-3, &out, nullptr, &near);
  QueryCounters full;
  (void)bvh.closest_point_counted(Vec3::Zero(), nullptr, &full);
  EXPECT_LT(near.nodes_visited * 5, full.nodes_visited);
  EXPECT_LT(near.nodes_visited, bvh.stats().nodes / 100);
}

TEST(MeshBvh, RefitAfterDeformationStaysExact) {
  TriangleMesh mesh = make_bumpy_sphere(6000);
  MeshBvh bvh(mesh);
  // Scale anisotropically and add a bulge: the old boxes would be far off.
  for (Vec3& v : mesh.vertices) {
    const double bulge = 1.0 + 0.5 * std::exp(-((v - Vec3(0.05, 0, 0)).squaredNorm()) / 4e-4);
    v = Vec3(1.3 * v.x(), 0.8 * v.y(), 1.1 * v.z()) * bulge;
  }
  bvh.refit();
  std::mt19937_64 rng(9);
  for (int i = 0; i < 1000; ++i) {
    const Vec3 p =
        i % 2 == 0 ? random_in_box(rng, mesh.bounds(), 0.5) : random_near_surface(rng, mesh, 2e-3);
    expect_matches_brute_force(bvh, mesh, p);
    if (i % 10 == 0 && std::abs(bvh.closest_point(p).signed_distance) > 1e-6) {
      EXPECT_EQ(bvh.closest_point(p).inside(), winding_number(mesh, p) > 0.5);
    }
  }
}

TEST(MeshBvh, StatsAndProgress) {
  const TriangleMesh mesh = make_bumpy_sphere(50000);
  int calls = 0;
  double last = -1.0;
  bool monotone = true;
  BvhBuildOptions options;
  options.progress = [&](std::string_view, double fraction) {
    monotone = monotone && fraction >= last;
    last = fraction;
    ++calls;
  };
  const MeshBvh bvh(mesh, options);
  EXPECT_GT(calls, 5);
  EXPECT_TRUE(monotone);
  EXPECT_EQ(last, 1.0);
  const BvhStats& s = bvh.stats();
  EXPECT_GT(s.nodes, 0u);
  EXPECT_GE(s.leaves, mesh.triangles.size() / 4);
  EXPECT_GT(s.depth, 3u);
  EXPECT_LT(s.depth, 40u);
  EXPECT_GE(s.build_ms, 0.0);
  EXPECT_EQ(s.memory_bytes, bvh.memory_bytes());
  EXPECT_GT(s.memory_bytes, bvh.signed_surface().memory_bytes());
  EXPECT_LT(s.memory_bytes, 80 * mesh.triangles.size());
  EXPECT_EQ(bvh.method_name(), "exact");
}

TEST(MeshBvh, EmptyAndDegenerateMeshes) {
  const TriangleMesh empty;
  const MeshBvh none(empty);
  EXPECT_FALSE(none.closest_point(Vec3::Zero()).found());
  EXPECT_FALSE(none.contact_within(Vec3::Zero(), 1.0, nullptr));
  // Many coincident triangles (all centroids equal) still build a bounded tree.
  TriangleMesh same;
  same.vertices = {Vec3(0, 0, 0), Vec3(1, 0, 0), Vec3(0, 1, 0)};
  same.triangles.assign(1000, TriangleIndices{0, 1, 2});
  const MeshBvh bvh(same);
  EXPECT_LT(bvh.stats().depth, 20u);
  EXPECT_NEAR(std::abs(bvh.closest_point(Vec3(0.1, 0.1, 1)).signed_distance), 1.0, 1e-15);
}

}  // namespace
}  // namespace hapsim
