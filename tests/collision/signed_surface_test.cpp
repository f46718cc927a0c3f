#include "hapsim/collision/signed_surface.h"

#include "hapsim/geometry/procedural.h"

#include <gtest/gtest.h>

#include <random>

namespace hapsim {
namespace {

// Brute-force closest triangle, resolved through SignedSurface.
SurfacePoint brute_resolve(const SignedSurface& sign, const TriangleMesh& mesh, const Vec3& p) {
  std::uint32_t best_t = kNoTriangle;
  TriangleClosest best{Vec3::Zero(), kInf, TriangleFeature::kFace};
  for (std::uint32_t t = 0; t < mesh.triangles.size(); ++t) {
    const auto [a, b, c] = mesh.corners(t);
    const TriangleClosest got = closest_point_on_triangle(p, a, b, c);
    if (got.distance_sq < best.distance_sq) {
      best = got;
      best_t = t;
    }
  }
  return sign.resolve(mesh, p, best_t, best);
}

TEST(SignedSurface, ClosedBoxHasNoOpenEdgesAndExactSigns) {
  const Vec3 half(0.01, 0.02, 0.03);
  const TriangleMesh box = make_box(half);
  const SignedSurface sign(box);
  EXPECT_EQ(sign.open_edge_count(), 0u);
  EXPECT_EQ(sign.non_manifold_edge_count(), 0u);
  for (std::uint32_t t = 0; t < box.triangles.size(); ++t) {
    for (int e = 0; e < 3; ++e) {
      EXPECT_LT(sign.neighbour(t, e), box.triangles.size());
    }
  }
  std::mt19937_64 rng(3);
  std::uniform_real_distribution<double> u(-2.0, 2.0);
  int inside = 0;
  for (int i = 0; i < 2000; ++i) {
    const Vec3 p = Vec3(u(rng), u(rng), u(rng)).cwiseProduct(half);
    const Vec3 q = p.cwiseAbs() - half;
    const bool expect_inside = q.maxCoeff() < 0.0;
    if (std::abs(q.maxCoeff()) < 1e-9) {
      continue;
    }
    const SurfacePoint sp = brute_resolve(sign, box, p);
    EXPECT_EQ(sp.inside(), expect_inside) << p.transpose();
    inside += expect_inside ? 1 : 0;
    // Outward normal points from the surface to p outside and away from p inside.
    EXPECT_NEAR(sp.normal.norm(), 1.0, 1e-12);
    EXPECT_GT(sp.normal.dot(p - sp.point) * sp.signed_distance, 0.0);
  }
  EXPECT_GT(inside, 100);  // the sample really hits both sides
}

TEST(SignedSurface, SheetGivesTheSideOfTheSurface) {
  const TriangleMesh sheet = make_sheet(5, 0.1);
  const SignedSurface sign(sheet);
  EXPECT_EQ(sign.open_edge_count(), 4u * 4u);  // 4 sides of 4 edges each
  std::mt19937_64 rng(5);
  std::uniform_real_distribution<double> u(-0.1, 0.1);
  for (int i = 0; i < 500; ++i) {
    const Vec3 p(u(rng), u(rng), u(rng));
    if (std::abs(p.z()) < 1e-9) {
      continue;
    }
    const SurfacePoint sp = brute_resolve(sign, sheet, p);
    EXPECT_EQ(sp.inside(), p.z() < 0.0) << p.transpose();
  }
}

TEST(SignedSurface, NonManifoldAndDegenerateInputDoesNotCrash) {
  // Three triangles on one edge (a fin), a degenerate triangle and an isolated open triangle.
  TriangleMesh mesh;
  mesh.vertices = {Vec3(0, 0, 0), Vec3(1, 0, 0), Vec3(0.5, 1, 0), Vec3(0.5, -1, 0), Vec3(0.5, 0, 1),
                   Vec3(2, 2, 2), Vec3(3, 2, 2), Vec3(2, 3, 2),   Vec3(4, 4, 4)};
  mesh.triangles = {{0, 1, 2}, {1, 0, 3}, {0, 1, 4}, {5, 6, 7}, {8, 8, 8}, {0, 0, 1}};
  const SignedSurface sign(mesh);
  EXPECT_GE(sign.non_manifold_edge_count(), 3u);
  EXPECT_GT(sign.open_edge_count(), 0u);
  EXPECT_GT(sign.memory_bytes(), 0u);
  std::mt19937_64 rng(9);
  std::uniform_real_distribution<double> u(-1.0, 5.0);
  for (int i = 0; i < 500; ++i) {
    const Vec3 p(u(rng), u(rng), u(rng));
    const SurfacePoint sp = brute_resolve(sign, mesh, p);
    ASSERT_TRUE(sp.found());
    EXPECT_TRUE(std::isfinite(sp.signed_distance));
    EXPECT_TRUE(sp.normal.allFinite());
    EXPECT_NEAR(sp.normal.norm(), 1.0, 1e-9);
  }
  SignedSurface moved = sign;
  mesh.vertices[4] = Vec3(0.5, 0.2, -1);
  moved.update_normals(mesh);  // must handle the non-manifold edge again
  const SurfacePoint sp = brute_resolve(moved, mesh, Vec3(0.5, 0.0, 0.5));
  EXPECT_TRUE(std::isfinite(sp.signed_distance));
}

TEST(SignedSurface, OnSurfaceNormalIsThePseudoNormal) {
  const TriangleMesh box = make_box(Vec3(1, 1, 1));
  const SignedSurface sign(box);
  // Exactly on the top face: distance 0, normal +z.
  const SurfacePoint face = brute_resolve(sign, box, Vec3(0.2, 0.3, 1.0));
  EXPECT_NEAR(face.signed_distance, 0.0, 1e-15);
  EXPECT_LT((face.normal - Vec3::UnitZ()).norm(), 1e-12);
  // Exactly on a corner: the vertex pseudo-normal points along the diagonal.
  const SurfacePoint corner = brute_resolve(sign, box, Vec3(1, 1, 1));
  EXPECT_LT((corner.normal - Vec3(1, 1, 1).normalized()).norm(), 1e-9);
}

}  // namespace
}  // namespace hapsim
