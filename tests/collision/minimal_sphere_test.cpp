#include "hapsim/collision/minimal_sphere.h"

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <random>
#include <vector>

namespace hapsim {
namespace {

constexpr double kTol = 1e-12;

bool contains(const Sphere& s, const Vec3& p, double tol = kTol) {
  return (p - s.center).norm() <= s.radius * (1.0 + tol) + 1e-300;
}

bool contains(const Sphere& s, const Sphere& inner, double tol = kTol) {
  return (inner.center - s.center).norm() + inner.radius <= s.radius * (1.0 + tol) + 1e-300;
}

// The true minimal sphere by exhaustion: it is the smallest candidate of some support set of
// 1–4 items that encloses everything.
template <typename T>
Sphere brute_force(const std::vector<T>& items, const auto& to_sphere) {
  const std::size_t n = items.size();
  Sphere best{Vec3::Zero(), kInf};
  std::vector<Sphere> all;
  for (const T& x : items) {
    all.push_back(to_sphere(x));
  }
  const auto consider = [&](std::span<const Sphere> support) {
    const std::optional<Sphere> s = sphere_through(support);
    if (!s || s->radius >= best.radius) {
      return;
    }
    for (const Sphere& x : all) {
      if (!contains(*s, x, 1e-9)) {
        return;
      }
    }
    best = *s;
  };
  for (std::size_t i = 0; i < n; ++i) {
    consider(std::span<const Sphere>(&all[i], 1));
    for (std::size_t j = i + 1; j < n; ++j) {
      const std::array<Sphere, 2> s2{all[i], all[j]};
      consider(s2);
      for (std::size_t k = j + 1; k < n; ++k) {
        const std::array<Sphere, 3> s3{all[i], all[j], all[k]};
        consider(s3);
        for (std::size_t l = k + 1; l < n; ++l) {
          const std::array<Sphere, 4> s4{all[i], all[j], all[k], all[l]};
          consider(s4);
        }
      }
    }
  }
  return best;
}

std::vector<Vec3> random_points(std::mt19937& rng, std::size_t n, double scale) {
  std::uniform_real_distribution<double> u(-scale, scale);
  std::vector<Vec3> pts(n);
  for (Vec3& p : pts) {
    p = Vec3(u(rng), u(rng), u(rng)) + Vec3(0.3, -0.2, 0.1);
  }
  return pts;
}

TEST(MinimalSphere, EmptyAndSinglePoint) {
  const Sphere empty = minimal_sphere(std::span<const Vec3>());
  EXPECT_EQ(empty.radius, 0.0);
  const std::vector<Vec3> one{Vec3(1, 2, 3)};
  const Sphere s = minimal_sphere(one);
  EXPECT_EQ(s.radius, 0.0);
  EXPECT_EQ(s.center, Vec3(1, 2, 3));
}

TEST(MinimalSphere, PointsOnACircle) {
  // Points on a tilted circle of radius 0.02 about c, plus points strictly inside the disc:
  // the answer is the circle's own sphere.
  const Vec3 c(0.1, -0.05, 0.2);
  const Vec3 e1 = Vec3(1, 1, 0).normalized();
  const Vec3 e2 = Vec3(-1, 1, 1).normalized().cross(e1).normalized();
  std::vector<Vec3> pts;
  for (int i = 0; i < 37; ++i) {
    const double a = 2.0 * std::numbers::pi * i / 37.0;
    pts.push_back(c + 0.02 * (std::cos(a) * e1 + std::sin(a) * e2));
    pts.push_back(c + 0.01 * (std::cos(3 * a) * e1 + std::sin(3 * a) * e2));
  }
  const Sphere s = minimal_sphere(pts);
  EXPECT_NEAR(s.radius, 0.02, 1e-14);
  EXPECT_NEAR((s.center - c).norm(), 0.0, 1e-14);
}

TEST(MinimalSphere, TetrahedronCorners) {
  // Regular tetrahedron: centred at its centroid with radius = circumradius.
  const double edge = 0.03;
  std::vector<Vec3> pts{Vec3(1, 1, 1), Vec3(1, -1, -1), Vec3(-1, 1, -1), Vec3(-1, -1, 1)};
  for (Vec3& p : pts) {
    p = p * (edge / std::sqrt(8.0)) + Vec3(0.5, 0.5, 0.5);
  }
  const Sphere s = minimal_sphere(pts);
  EXPECT_NEAR(s.radius, edge * std::sqrt(6.0) / 4.0, 1e-15);
  EXPECT_NEAR((s.center - Vec3(0.5, 0.5, 0.5)).norm(), 0.0, 1e-15);

  // A flat (obtuse) tetrahedron's minimal sphere is NOT its circumsphere: it is set by the
  // longest edge only.
  const std::vector<Vec3> flat{Vec3(-1, 0, 0), Vec3(1, 0, 0), Vec3(0, 0.1, 0.01),
                               Vec3(0, -0.1, -0.01)};
  const Sphere f = minimal_sphere(flat);
  EXPECT_NEAR(f.radius, 1.0, 1e-15);
  EXPECT_NEAR(f.center.norm(), 0.0, 1e-15);
}

TEST(MinimalSphere, DegenerateSets) {
  // Collinear points and duplicates: the support solve is singular and must fall back.
  std::vector<Vec3> line;
  for (int i = 0; i <= 10; ++i) {
    line.push_back(Vec3(i, 2.0 * i, -i) * 0.01);
    line.push_back(Vec3(i, 2.0 * i, -i) * 0.01);
  }
  const Sphere s = minimal_sphere(line);
  EXPECT_NEAR(s.radius, 0.5 * (line.back() - line.front()).norm(), 1e-15);
  for (const Vec3& p : line) {
    EXPECT_TRUE(contains(s, p));
  }
  // Square corners (four co-circular points: the 4-point solve is singular).
  const std::vector<Vec3> square{Vec3(1, 1, 0), Vec3(-1, 1, 0), Vec3(-1, -1, 0), Vec3(1, -1, 0)};
  EXPECT_NEAR(minimal_sphere(square).radius, std::sqrt(2.0), 1e-14);
}

TEST(MinimalSphere, RandomSetsMatchBruteForceAndBeatRitter) {
  std::mt19937 rng(7);
  for (int trial = 0; trial < 200; ++trial) {
    const std::size_t n = 2 + static_cast<std::size_t>(trial % 9);
    std::vector<Vec3> pts = random_points(rng, n, 0.05);
    const Sphere s = minimal_sphere(pts);
    for (const Vec3& p : pts) {
      ASSERT_TRUE(contains(s, p)) << "trial " << trial;
    }
    const Sphere ritter = ritter_sphere(pts);
    EXPECT_LE(s.radius, ritter.radius * (1.0 + 1e-12));
    const Sphere exact = brute_force(pts, [](const Vec3& p) { return Sphere{p, 0.0}; });
    EXPECT_NEAR(s.radius, exact.radius, 1e-12 * exact.radius) << "trial " << trial;
    EXPECT_NEAR((s.center - exact.center).norm(), 0.0, 1e-9 * exact.radius);
  }
}

TEST(MinimalSphere, LargeRandomSetEnclosedAndTighterThanRitter) {
  std::mt19937 rng(11);
  // Points on and in an ellipsoid: the minimal sphere touches the long axis.
  std::normal_distribution<double> g(0.0, 1.0);
  std::vector<Vec3> pts;
  for (int i = 0; i < 20000; ++i) {
    Vec3 d(g(rng), g(rng), g(rng));
    d.normalize();
    pts.push_back(Vec3(0.1 * d.x(), 0.03 * d.y(), 0.02 * d.z()));
  }
  pts.push_back(Vec3(0.1, 0, 0));
  pts.push_back(Vec3(-0.1, 0, 0));
  const Sphere s = minimal_sphere(pts);
  EXPECT_NEAR(s.radius, 0.1, 1e-12);
  for (const Vec3& p : pts) {
    ASSERT_TRUE(contains(s, p));
  }
  EXPECT_LE(s.radius, ritter_sphere(pts).radius);
}

TEST(MinimalSphere, TriangleClosedFormMatchesWelzl) {
  std::mt19937 rng(5);
  int obtuse = 0;
  for (int trial = 0; trial < 2000; ++trial) {
    const std::vector<Vec3> abc = random_points(rng, 3, 0.01);
    const Sphere s = triangle_sphere(abc[0], abc[1], abc[2]);
    const Sphere w = minimal_sphere(abc);
    EXPECT_NEAR(s.radius, w.radius, 1e-14);
    EXPECT_NEAR((s.center - w.center).norm(), 0.0, 1e-12);
    for (const Vec3& p : abc) {
      EXPECT_LE((p - s.center).norm(), s.radius);
    }
    obtuse += (abc[1] - abc[0]).dot(abc[2] - abc[0]) < 0.0 ? 1 : 0;
  }
  EXPECT_GT(obtuse, 100);  // both branches exercised
  const Sphere degenerate = triangle_sphere(Vec3(0, 0, 0), Vec3(1, 0, 0), Vec3(3, 0, 0));
  EXPECT_NEAR(degenerate.radius, 1.5, 1e-15);
}

TEST(MinimalSphere, SphereThroughSupportSets) {
  // Three points of a right triangle: circumcircle centred on the hypotenuse.
  const std::array<Sphere, 3> tri{Sphere{Vec3(0, 0, 0), 0}, Sphere{Vec3(2, 0, 0), 0},
                                  Sphere{Vec3(0, 2, 0), 0}};
  const std::optional<Sphere> s = sphere_through(tri);
  ASSERT_TRUE(s.has_value());
  EXPECT_NEAR((s->center - Vec3(1, 1, 0)).norm(), 0.0, 1e-15);
  EXPECT_NEAR(s->radius, std::sqrt(2.0), 1e-15);
  // Two equal balls: the answer spans both.
  const std::array<Sphere, 2> two{Sphere{Vec3(-1, 0, 0), 0.5}, Sphere{Vec3(1, 0, 0), 0.5}};
  const std::optional<Sphere> t = sphere_through(two);
  ASSERT_TRUE(t.has_value());
  EXPECT_NEAR(t->radius, 1.5, 1e-15);
  EXPECT_NEAR(t->center.norm(), 0.0, 1e-15);
  // Collinear points have no circumcircle.
  const std::array<Sphere, 3> line{Sphere{Vec3(0, 0, 0), 0}, Sphere{Vec3(1, 0, 0), 0},
                                   Sphere{Vec3(2, 0, 0), 0}};
  EXPECT_FALSE(sphere_through(line).has_value());
}

TEST(EnclosingSphere, KnownAnswers) {
  // Nested: the outer ball itself.
  const std::vector<Sphere> nested{Sphere{Vec3(0.01, 0, 0), 0.01}, Sphere{Vec3::Zero(), 0.05},
                                   Sphere{Vec3(0, -0.02, 0.01), 0.02}};
  const Sphere n = enclosing_sphere(nested);
  EXPECT_NEAR(n.radius, 0.05, 1e-15);
  EXPECT_NEAR(n.center.norm(), 0.0, 1e-15);
  // Two balls: the ball spanning their far sides.
  const std::vector<Sphere> pair{Sphere{Vec3(0, 0, 0), 0.01}, Sphere{Vec3(0.1, 0, 0), 0.03}};
  const Sphere p = enclosing_sphere(pair);
  EXPECT_NEAR(p.radius, 0.5 * (0.1 + 0.01 + 0.03), 1e-15);
  EXPECT_NEAR((p.center - Vec3(0.06, 0, 0)).norm(), 0.0, 1e-15);
  // Four equal balls on a regular tetrahedron: concentric, radius = circumradius + r.
  std::vector<Sphere> tet;
  for (const Vec3& v : {Vec3(1, 1, 1), Vec3(1, -1, -1), Vec3(-1, 1, -1), Vec3(-1, -1, 1)}) {
    tet.push_back({v, 0.25});
  }
  const Sphere t = enclosing_sphere(tet);
  EXPECT_NEAR(t.radius, std::sqrt(3.0) + 0.25, 1e-14);
  EXPECT_NEAR(t.center.norm(), 0.0, 1e-14);
}

TEST(EnclosingSphere, RandomSetsEncloseAndMatchBruteForce) {
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> ur(0.0, 0.02);
  int matched = 0;
  const int trials = 300;
  for (int trial = 0; trial < trials; ++trial) {
    const std::size_t n = 2 + static_cast<std::size_t>(trial % 7);
    const std::vector<Vec3> centers = random_points(rng, n, 0.05);
    std::vector<Sphere> spheres;
    for (const Vec3& c : centers) {
      spheres.push_back({c, ur(rng)});
    }
    const Sphere s = enclosing_sphere(spheres);
    for (const Sphere& x : spheres) {
      ASSERT_TRUE(contains(s, x)) << "trial " << trial;
    }
    const Sphere exact = brute_force(spheres, [](const Sphere& x) { return x; });
    // Never smaller than the true minimum (that would mean a child pokes out).
    EXPECT_GE(s.radius, exact.radius * (1.0 - 1e-9));
    // Welzl on balls is minimal in generic position; allow a rare miss, but bound it.
    EXPECT_LE(s.radius, exact.radius * 1.05) << "trial " << trial;
    if (s.radius <= exact.radius * (1.0 + 1e-9)) {
      ++matched;
    }
  }
  EXPECT_GE(matched, trials * 95 / 100);
}

}  // namespace
}  // namespace hapsim
