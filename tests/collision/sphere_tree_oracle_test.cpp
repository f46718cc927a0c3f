// The sphere tree's exact answers against CGAL's AABB_tree (an independent implementation of
// closest point on a triangle soup): same distance to 1e-9 relative, same point.
#include "hapsim/collision/sphere_tree.h"

#include "hapsim/geometry/procedural.h"
#include "oracles/closest_point_oracle.h"

#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <vector>

namespace hapsim {
namespace {

std::vector<Vec3> query_points(const TriangleMesh& mesh, std::size_t count, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_int_distribution<std::size_t> pick(0, mesh.triangle_count() - 1);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  const Box3 box = mesh.bounds();
  std::vector<Vec3> pts;
  for (std::size_t i = 0; i < count; ++i) {
    if (i % 2 == 0) {
      // Within 3 mm of the surface, either side.
      const auto c = mesh.corners(pick(rng));
      const double a = unit(rng);
      const double b = (1.0 - a) * unit(rng);
      const Vec3 n = (c[1] - c[0]).cross(c[2] - c[0]).normalized();
      pts.push_back(c[0] + a * (c[1] - c[0]) + b * (c[2] - c[0]) +
                    (2.0 * unit(rng) - 1.0) * 0.003 * n);
    } else {
      // Anywhere in a box twice the body's size.
      const Vec3 u(unit(rng), unit(rng), unit(rng));
      pts.push_back(box.center() + (2.0 * u - Vec3::Ones()).cwiseProduct(box.sizes()));
    }
  }
  return pts;
}

void compare_with_cgal(const TriangleMesh& mesh, unsigned seed) {
#ifdef HAPSIM_HAVE_CGAL
  const auto cgal = oracle::make_oracle("cgal", mesh);
  ASSERT_NE(cgal, nullptr);
  const SphereTree tree(mesh);
  QueryHint hint;
  std::size_t checked = 0;
  for (const Vec3& p : query_points(mesh, 2000, seed)) {
    const oracle::OracleAnswer want = cgal->closest(p);
    for (QueryHint* h : {static_cast<QueryHint*>(nullptr), &hint}) {
      const SurfacePoint got = tree.closest_point(p, h);
      ASSERT_TRUE(got.found());
      const double tol = 1e-9 * std::max(want.distance, 1e-6);
      EXPECT_NEAR(std::abs(got.signed_distance), want.distance, tol) << p.transpose();
      // The points agree unless the distance is shared by two places (then either is right).
      if ((got.point - want.point).norm() > tol) {
        EXPECT_NEAR((want.point - p).norm(), std::abs(got.signed_distance), tol);
      }
      ++checked;
    }
  }
  EXPECT_EQ(checked, 4000U);
#else
  (void)mesh;
  (void)seed;
  GTEST_SKIP() << "built without CGAL";
#endif
}

TEST(SphereTreeOracle, BumpySphereAgreesWithCgal) {
  compare_with_cgal(make_bumpy_sphere(13500), 1);
}

TEST(SphereTreeOracle, SheetAgreesWithCgal) {
  compare_with_cgal(make_sheet(51, 0.2), 2);
}

TEST(SphereTreeOracle, BoxAgreesWithCgal) {
  compare_with_cgal(make_box(Vec3(0.03, 0.02, 0.01)), 3);
}

TEST(SphereTreeOracle, RefittedBumpySphereAgreesWithCgalOnTheMovedMesh) {
  TriangleMesh mesh = make_bumpy_sphere(5000);
  SphereTree tree(mesh);
  for (Vec3& v : mesh.vertices) {
    v.x() *= 1.0 + 0.3 * std::exp(-v.y() * v.y() / 4e-4);  // stretch a band along x
  }
  tree.refit();
#ifdef HAPSIM_HAVE_CGAL
  const auto cgal = oracle::make_oracle("cgal", mesh);
  ASSERT_NE(cgal, nullptr);
  QueryHint hint;
  for (const Vec3& p : query_points(mesh, 1000, 4)) {
    const double want = cgal->closest(p).distance;
    const SurfacePoint got = tree.closest_point(p, &hint);
    EXPECT_NEAR(std::abs(got.signed_distance), want, 1e-9 * std::max(want, 1e-6));
  }
#else
  GTEST_SKIP() << "built without CGAL";
#endif
}

}  // namespace
}  // namespace hapsim
