#include "hapsim/collision/point_triangle.h"

#include <gtest/gtest.h>

#include <cmath>
#include <random>

namespace hapsim {
namespace {

// Brute force: the nearest of a dense barycentric grid (plus the exact edges, sampled densely).
double brute_distance(const Vec3& p, const Vec3& a, const Vec3& b, const Vec3& c, int n) {
  double best = kInf;
  for (int i = 0; i <= n; ++i) {
    for (int j = 0; i + j <= n; ++j) {
      const double u = static_cast<double>(i) / n;
      const double v = static_cast<double>(j) / n;
      const Vec3 q = a + u * (b - a) + v * (c - a);
      best = std::min(best, (p - q).norm());
    }
  }
  return best;
}

// Longest edge / n bounds how far the grid's nearest sample can be from the true closest point.
double grid_spacing(const Vec3& a, const Vec3& b, const Vec3& c, int n) {
  return std::max({(b - a).norm(), (c - b).norm(), (a - c).norm()}) / n;
}

// Whether q lies in triangle (a, b, c) (up to rounding).
bool on_triangle(const Vec3& q, const Vec3& a, const Vec3& b, const Vec3& c) {
  const Vec3 n = (b - a).cross(c - a);
  const double scale = std::max({(b - a).norm(), (c - a).norm(), 1e-300});
  if (n.norm() < 1e-14 * scale * scale) {
    return true;  // degenerate: checked by distance only
  }
  const double tol = 1e-9 * scale * scale;
  return std::abs(n.normalized().dot(q - a)) < 1e-9 * scale && (b - a).cross(q - a).dot(n) > -tol &&
         (c - b).cross(q - b).dot(n) > -tol && (a - c).cross(q - c).dot(n) > -tol;
}

TEST(PointTriangle, MatchesBarycentricSamplingOnRandomTriangles) {
  std::mt19937_64 rng(7);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  constexpr int kGrid = 300;
  for (int trial = 0; trial < 200; ++trial) {
    const Vec3 a(u(rng), u(rng), u(rng));
    const Vec3 b(u(rng), u(rng), u(rng));
    const Vec3 c(u(rng), u(rng), u(rng));
    const Vec3 p = 2.0 * Vec3(u(rng), u(rng), u(rng));
    const TriangleClosest got = closest_point_on_triangle(p, a, b, c);
    const double brute = brute_distance(p, a, b, c, kGrid);
    const double d = std::sqrt(got.distance_sq);
    // Exact answer is never beaten by a sample, and a sample lies within one spacing of it.
    EXPECT_LE(d, brute + 1e-12) << "trial " << trial;
    EXPECT_GE(d, brute - grid_spacing(a, b, c, kGrid)) << "trial " << trial;
    EXPECT_NEAR((p - got.point).squaredNorm(), got.distance_sq, 1e-12);
    EXPECT_TRUE(on_triangle(got.point, a, b, c)) << "trial " << trial;
  }
}

TEST(PointTriangle, ReportsTheFeatureOfEachVoronoiRegion) {
  const Vec3 a(0, 0, 0);
  const Vec3 b(1, 0, 0);
  const Vec3 c(0, 1, 0);
  struct Case {
    Vec3 p;
    TriangleFeature feature;
    Vec3 point;
  };
  const Case cases[] = {
      {Vec3(-1, -1, 0.5), TriangleFeature::kVertexA, a},
      {Vec3(2, -0.5, -1), TriangleFeature::kVertexB, b},
      {Vec3(-0.5, 2, 3), TriangleFeature::kVertexC, c},
      {Vec3(0.5, -1, 0), TriangleFeature::kEdgeAB, Vec3(0.5, 0, 0)},
      {Vec3(1, 1, 0.2), TriangleFeature::kEdgeBC, Vec3(0.5, 0.5, 0)},
      {Vec3(-3, 0.25, 0), TriangleFeature::kEdgeCA, Vec3(0, 0.25, 0)},
      {Vec3(0.2, 0.3, -4), TriangleFeature::kFace, Vec3(0.2, 0.3, 0)},
  };
  for (const Case& cs : cases) {
    const TriangleClosest got = closest_point_on_triangle(cs.p, a, b, c);
    EXPECT_EQ(got.feature, cs.feature) << cs.p.transpose();
    EXPECT_LT((got.point - cs.point).norm(), 1e-15) << cs.p.transpose();
    EXPECT_DOUBLE_EQ(got.distance_sq, (cs.p - cs.point).squaredNorm());
  }
}

TEST(PointTriangle, DegenerateTrianglesGiveFiniteExactAnswers) {
  std::mt19937_64 rng(11);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  for (int trial = 0; trial < 300; ++trial) {
    const Vec3 a(u(rng), u(rng), u(rng));
    const Vec3 d(u(rng), u(rng), u(rng));
    Vec3 b;
    Vec3 c;
    switch (trial % 4) {
      case 0:
        b = a;
        c = a + d;
        break;  // a == b: segment
      case 1:
        b = a + d;
        c = b;
        break;  // b == c
      case 2:
        b = a + d;
        c = a + 0.3 * d;
        break;  // collinear, distinct
      default:
        b = a;
        c = a;
        break;  // a point
    }
    const Vec3 p = 2.0 * Vec3(u(rng), u(rng), u(rng));
    const TriangleClosest got = closest_point_on_triangle(p, a, b, c);
    ASSERT_TRUE(std::isfinite(got.distance_sq)) << "trial " << trial;
    ASSERT_TRUE(got.point.allFinite()) << "trial " << trial;
    // Exact for a segment: the hull of the three points is the segment between the extremes.
    double best = kInf;
    const Vec3 pts[3] = {a, b, c};
    for (int i = 0; i < 3; ++i) {
      for (int j = 0; j < 3; ++j) {
        const Vec3 e = pts[j] - pts[i];
        const double len2 = e.squaredNorm();
        const double t = len2 > 0 ? std::clamp((p - pts[i]).dot(e) / len2, 0.0, 1.0) : 0.0;
        best = std::min(best, (p - (pts[i] + t * e)).squaredNorm());
      }
    }
    EXPECT_NEAR(got.distance_sq, best, 1e-12 * (1.0 + best)) << "trial " << trial;
  }
}

}  // namespace
}  // namespace hapsim
