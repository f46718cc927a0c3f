#include "hapsim/geometry/csg.h"

#include "hapsim/core/error.h"

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <random>
#include <vector>

namespace hapsim {
namespace {

constexpr double kTol = 1e-12;

void expect_sample(const CsgSolid& s, const Vec3& p, double d, const Vec3& g) {
  const SdfSample r = s.evaluate(p);
  EXPECT_NEAR(r.distance_m, d, kTol) << "at " << p.transpose();
  EXPECT_NEAR((r.gradient - g).norm(), 0.0, 1e-12)
      << "at " << p.transpose() << ": gradient " << r.gradient.transpose() << " expected "
      << g.transpose();
  EXPECT_DOUBLE_EQ(s.distance(p), r.distance_m);
}

void expect_distance(const CsgSolid& s, const Vec3& p, double d) {
  EXPECT_NEAR(s.evaluate(p).distance_m, d, kTol) << "at " << p.transpose();
}

Vec3 fd_gradient(const CsgSolid& s, const Vec3& p, double e) {
  Vec3 g;
  for (int a = 0; a < 3; ++a) {
    Vec3 dp = Vec3::Zero();
    dp[a] = e;
    g[a] = (s.distance(p + dp) - s.distance(p - dp)) / (2 * e);
  }
  return g;
}

// Gradient vs central differences at random points. Points on (within e of) a medial axis have a
// finite-difference gradient shorter than 1 and are skipped — but most points must be checked,
// so a formula that is wrong everywhere cannot hide behind the skip.
void check_gradients(const CsgSolid& s, const Box3& region, int samples = 4000) {
  std::mt19937 rng(42);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  int checked = 0;
  const double e = 1e-6 * region.sizes().norm();
  for (int n = 0; n < samples; ++n) {
    const Vec3 p = region.min() + region.sizes().cwiseProduct(Vec3(u(rng), u(rng), u(rng)));
    const SdfSample r = s.evaluate(p);
    ASSERT_NEAR(r.gradient.norm(), 1.0, 1e-12) << "at " << p.transpose();
    const Vec3 fd = fd_gradient(s, p, e);
    if (fd.norm() < 1.0 - 1e-6) {
      continue;  // medial axis (kink) within e
    }
    ++checked;
    EXPECT_NEAR((fd - r.gradient).norm(), 0.0, 1e-5) << "at " << p.transpose();
  }
  EXPECT_GT(checked, samples * 9 / 10);
}

// Points on the surface, by bisecting random inside→outside segments (needs only exact signs).
std::vector<Vec3> surface_points(const CsgSolid& s, const Box3& region, int count) {
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  std::vector<Vec3> inside;
  std::vector<Vec3> outside;
  while (inside.size() < 200 || outside.size() < 200) {
    const Vec3 p = region.min() + region.sizes().cwiseProduct(Vec3(u(rng), u(rng), u(rng)));
    (s.distance(p) < 0 ? inside : outside).push_back(p);
  }
  std::vector<Vec3> out;
  for (int n = 0; n < count; ++n) {
    Vec3 a = inside[n % inside.size()];
    Vec3 b = outside[(n * 7 + n / 200) % outside.size()];
    for (int it = 0; it < 60; ++it) {
      const Vec3 m = 0.5 * (a + b);
      (s.distance(m) < 0 ? a : b) = m;
    }
    out.push_back(0.5 * (a + b));
  }
  return out;
}

// For every tree: |d| never exceeds the distance to any surface point (conservative); where the
// sample says exact, the foot point p − d·g is on the surface (so |d| is attained: exact).
enum class Exact { kEverywhere, kSomewhere, kNowhere };

void check_distance_bound(const CsgSolid& s, const Box3& region, Exact expected) {
  const std::vector<Vec3> surface = surface_points(s, region, 3000);
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  const double eps = 1e-9 * region.sizes().norm();
  int exact_count = 0;
  for (int n = 0; n < 1000; ++n) {
    const Vec3 p = region.min() + region.sizes().cwiseProduct(Vec3(u(rng), u(rng), u(rng)));
    const SdfSample r = s.evaluate(p);
    double nearest = kInf;
    for (const Vec3& q : surface) {
      nearest = std::min(nearest, (p - q).norm());
    }
    EXPECT_LE(std::abs(r.distance_m), nearest + eps) << "at " << p.transpose();
    if (expected == Exact::kEverywhere) {
      EXPECT_TRUE(r.exact) << "at " << p.transpose();
    }
    if (r.exact) {
      ++exact_count;
      const Vec3 foot = p - r.distance_m * r.gradient;
      EXPECT_NEAR(s.distance(foot), 0.0, eps) << "foot of " << p.transpose();
    }
  }
  if (expected == Exact::kNowhere) {
    EXPECT_EQ(exact_count, 0);
  } else {
    EXPECT_GT(exact_count, 0);
  }
}

const Box3 kRegion(Vec3(-3, -3, -4), Vec3(3, 3, 4));

TEST(CsgTest, SphereAnalytic) {
  const CsgSolid s = CsgSolid::sphere(0.5);
  expect_sample(s, Vec3(1, 0, 0), 0.5, Vec3(1, 0, 0));
  expect_sample(s, Vec3(0, -0.2, 0), -0.3, Vec3(0, -1, 0));
  expect_sample(s, Vec3(0.3, 0.4, 0), 0.0, Vec3(0.6, 0.8, 0));
  expect_sample(s, Vec3(2, 2, 1), 2.5, Vec3(2, 2, 1) / 3.0);
  EXPECT_NEAR(s.distance(Vec3::Zero()), -0.5, kTol);
  EXPECT_NEAR(s.evaluate(Vec3::Zero()).gradient.norm(), 1.0, kTol);
  EXPECT_TRUE(s.contains(Vec3(0.1, 0.1, 0.1)));
  EXPECT_FALSE(s.contains(Vec3(0.5, 0.5, 0)));
  EXPECT_TRUE(s.evaluate(Vec3(3, 0, 0)).exact);
  check_gradients(s, kRegion);
  check_distance_bound(s, kRegion, Exact::kEverywhere);
}

TEST(CsgTest, BlockFacesEdgesCorners) {
  const CsgSolid b = CsgSolid::block(Vec3(1, 2, 3));
  expect_sample(b, Vec3(0.5, 0, 0), -0.5, Vec3(1, 0, 0));        // inside, nearest face +x
  expect_sample(b, Vec3(0, -1.9, 0.5), -0.1, Vec3(0, -1, 0));    // inside, near −y face
  expect_sample(b, Vec3(0, 0, -2.5), -0.5, Vec3(0, 0, -1));      // inside, nearest −z
  expect_sample(b, Vec3(3, 0, 0), 2.0, Vec3(1, 0, 0));           // outside a face
  expect_sample(b, Vec3(2, 3, 0), std::sqrt(2.0), Vec3(1, 1, 0) / std::sqrt(2.0));  // edge
  expect_sample(b, Vec3(-2, -4, 5), 3.0, Vec3(-1, -2, 2) / 3.0);  // corner region: |p − corner|
  expect_sample(b, Vec3(1, 0.5, 0.5), 0.0, Vec3(1, 0, 0));       // on a face
  expect_distance(b, Vec3(1, 2, 3), 0.0);                         // the corner itself
  check_gradients(b, kRegion);
  check_distance_bound(b, kRegion, Exact::kEverywhere);
}

TEST(CsgTest, CylinderSideCapsAndRim) {
  const CsgSolid c = CsgSolid::cylinder(1.0, 2.0);
  expect_sample(c, Vec3(0.5, 0, 1.8), -0.2, Vec3(0, 0, 1));      // inside, nearest the top cap
  expect_sample(c, Vec3(0, 0.7, 0), -0.3, Vec3(0, 1, 0));        // inside, nearest the side
  expect_sample(c, Vec3(0, 3, 0), 2.0, Vec3(0, 1, 0));           // outside the side
  expect_sample(c, Vec3(0.5, 0, -3), 1.0, Vec3(0, 0, -1));       // below the bottom cap
  const double a = 0.7;
  // Rim region: ρ − r = 1, z − h = 1 → distance to the rim circle √2.
  expect_sample(c, Vec3(2 * std::cos(a), 2 * std::sin(a), 3), std::sqrt(2.0),
                Vec3(std::cos(a), std::sin(a), 1) / std::sqrt(2.0));
  expect_sample(c, Vec3(1.3 * std::cos(a), 1.3 * std::sin(a), -2.4), 0.5,
                Vec3(0.6 * std::cos(a), 0.6 * std::sin(a), -0.8));
  expect_distance(c, Vec3(std::cos(a), std::sin(a), 0.3), 0.0);
  check_gradients(c, kRegion);
  check_distance_bound(c, kRegion, Exact::kEverywhere);
}

TEST(CsgTest, ConeApexRimSideBase) {
  // Base radius 1 at z = 0, apex at z = 2; side line 2ρ + z = 2, outward normal (2, 1)/√5.
  const CsgSolid c = CsgSolid::cone(1.0, 2.0);
  const double s5 = std::sqrt(5.0);
  const Vec3 n(2 / s5, 0, 1 / s5);
  expect_sample(c, Vec3(0, 0, 3), 1.0, Vec3(0, 0, 1));  // above the apex
  // Apex region: the foot on the side line would lie beyond the apex, so distance to the apex.
  expect_sample(c, Vec3(0.2, 0, 3), std::sqrt(1.04), Vec3(0.2, 0, 1) / std::sqrt(1.04));
  const Vec3 mid(0.5, 0, 1);  // middle of the side
  expect_sample(c, mid + 0.3 * n, 0.3, n);
  expect_sample(c, mid - 0.1 * n, -0.1, n);
  expect_sample(c, Vec3(1.3, 0, -0.4), 0.5, Vec3(0.6, 0, -0.8));  // base rim region
  expect_sample(c, Vec3(0.5, 0, -1), 1.0, Vec3(0, 0, -1));        // below the base
  expect_sample(c, Vec3(0.2, 0, 0.05), -0.05, Vec3(0, 0, -1));    // inside, near the base
  expect_distance(c, Vec3(0, 0, 2), 0.0);                         // the apex itself
  expect_distance(c, Vec3(0, -0.5, 1), 0.0);                      // on the side
  // Rotational symmetry: the same side point turned about z.
  const double a = 2.0;
  const Vec3 na(2 / s5 * std::cos(a), 2 / s5 * std::sin(a), 1 / s5);
  expect_sample(c, Vec3(0.5 * std::cos(a), 0.5 * std::sin(a), 1) + 0.3 * na, 0.3, na);
  check_gradients(c, kRegion);
  check_distance_bound(c, kRegion, Exact::kEverywhere);
}

TEST(CsgTest, FrustumTopCapAndRims) {
  const CsgSolid f = CsgSolid::frustum(1.0, 0.5, 1.0);  // z ∈ [−1, 1]
  expect_sample(f, Vec3(0.2, 0, 1.5), 0.5, Vec3(0, 0, 1));          // above the top cap
  expect_sample(f, Vec3(0.5 + 0.3, 0, 1.4), 0.5, Vec3(0.6, 0, 0.8));  // top rim region
  expect_sample(f, Vec3(0, 0, -0.9), -0.1, Vec3(0, 0, -1));         // inside near the bottom
  // Side line through (1, −1) and (0.5, 1): normal (2, 0.5)/|.|.
  const Vec3 n = Vec3(2, 0, 0.5).normalized();
  expect_sample(f, Vec3(0.75, 0, 0) + 0.2 * n, 0.2, n);
  check_gradients(f, kRegion);
  check_distance_bound(f, kRegion, Exact::kEverywhere);
}

TEST(CsgTest, TorusAnalytic) {
  const CsgSolid t = CsgSolid::torus(1.0, 0.25);
  expect_distance(t, Vec3(1, 0, 0), -0.25);                         // tube centre circle
  expect_sample(t, Vec3(2, 0, 0), 0.75, Vec3(1, 0, 0));             // outside, in the plane
  expect_sample(t, Vec3(0, 0.5, 0), 0.25, Vec3(0, -1, 0));          // in the hole
  expect_sample(t, Vec3(0, 1, 0.5), 0.25, Vec3(0, 0, 1));           // above the tube
  expect_distance(t, Vec3(0, 0, 0), 0.75);                          // centre (medial axis)
  expect_distance(t, Vec3(0, 0, 2), std::sqrt(5.0) - 0.25);         // on the axis
  const double a = -1.1;
  expect_sample(t, Vec3(1.3 * std::cos(a), 1.3 * std::sin(a), 0.4), 0.25,
                Vec3(0.6 * std::cos(a), 0.6 * std::sin(a), 0.8));
  expect_sample(t, Vec3(1.06 * std::cos(a), 1.06 * std::sin(a), -0.08), -0.15,
                Vec3(0.6 * std::cos(a), 0.6 * std::sin(a), -0.8));
  check_gradients(t, kRegion);
  check_distance_bound(t, kRegion, Exact::kEverywhere);
}

TEST(CsgTest, RigidTransforms) {
  const Iso3 X_PS = Eigen::Translation3d(1, 2, 3) * Eigen::AngleAxisd(0.9, Vec3(1, 2, -1).normalized());
  const CsgSolid ball = CsgSolid::sphere(0.5).transformed(X_PS);
  expect_sample(ball, Vec3(1, 2, 4), 0.5, Vec3(0, 0, 1));  // a sphere only moves its centre
  // A block turned 90° about z swaps its x and y half extents.
  const CsgSolid b = CsgSolid::block(Vec3(1, 2, 3)).transformed(
      Iso3(Eigen::AngleAxisd(std::numbers::pi / 2, Vec3::UnitZ())));
  expect_sample(b, Vec3(1.5, 0, 0), -0.5, Vec3(1, 0, 0));
  expect_sample(b, Vec3(0, 1.5, 0), 0.5, Vec3(0, 1, 0));
  // General case: value equals the child's at X⁻¹p, gradient rotated.
  const CsgSolid cyl = CsgSolid::cylinder(0.4, 0.8);
  const CsgSolid moved = cyl.transformed(X_PS);
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> u(-2.0, 2.0);
  for (int n = 0; n < 200; ++n) {
    const Vec3 p = X_PS.translation() + Vec3(u(rng), u(rng), u(rng));
    const SdfSample child = cyl.evaluate(X_PS.inverse() * p);
    const SdfSample s = moved.evaluate(p);
    EXPECT_NEAR(s.distance_m, child.distance_m, 1e-12);
    EXPECT_NEAR((s.gradient - X_PS.linear() * child.gradient).norm(), 0.0, 1e-12);
  }
  // Nested transforms compose into one node.
  const CsgSolid twice = moved.transformed(X_PS.inverse());
  EXPECT_EQ(twice.node_count(), 2U);
  expect_distance(twice, Vec3(0, 0, 0.9), 0.1);
  check_gradients(moved, Box3(Vec3(-1, 0, 1), Vec3(3, 4, 5)));
  // Bounds stay conservative under rotation.
  const Box3 bb = moved.bounds();
  for (const Vec3& q : surface_points(moved, Box3(Vec3(-1, 0, 1), Vec3(3, 4, 5)), 500)) {
    EXPECT_TRUE(bb.contains(q)) << q.transpose();
  }
}

TEST(CsgTest, DifferenceBoxMinusSphere) {
  const CsgSolid shell = CsgSolid::block(Vec3(1, 1, 1)) - CsgSolid::sphere(0.5);
  // Inside the cavity: outside the solid, 0.5 from the cavity wall (a bound, here tight).
  const SdfSample cavity = shell.evaluate(Vec3::Zero());
  EXPECT_NEAR(cavity.distance_m, 0.5, kTol);
  EXPECT_FALSE(cavity.exact);
  expect_sample(shell, Vec3(0, 0.2, 0), 0.3, Vec3(0, -1, 0));  // in the cavity, off-centre
  // In the remaining shell: exact, gradient of whichever surface is nearer.
  expect_sample(shell, Vec3(0.8, 0, 0), -0.2, Vec3(1, 0, 0));    // nearer the outer face
  expect_sample(shell, Vec3(0, 0.6, 0), -0.1, Vec3(0, -1, 0));   // nearer the cavity
  expect_sample(shell, Vec3(0.7, 0.7, 0.7), -0.3, Vec3(1, 0, 0));  // corner: three faces tie
  EXPECT_TRUE(shell.evaluate(Vec3(0.8, 0, 0)).exact);
  expect_distance(shell, Vec3(2, 0, 0), 1.0);      // outside
  expect_distance(shell, Vec3(2, 2, 2), std::sqrt(3.0));
  expect_distance(shell, Vec3(0, 0.5, 0), 0.0);    // on the cavity wall
  EXPECT_FALSE(shell.contains(Vec3(0.1, 0, 0)));
  EXPECT_TRUE(shell.contains(Vec3(0.9, 0.9, 0.9)));
  check_gradients(shell, Box3(Vec3(-2, -2, -2), Vec3(2, 2, 2)));
  check_distance_bound(shell, Box3(Vec3(-2, -2, -2), Vec3(2, 2, 2)), Exact::kSomewhere);
}

TEST(CsgTest, UnionAndIntersectionOfSpheres) {
  const CsgSolid a = CsgSolid::sphere(1.0).transformed(Iso3(Eigen::Translation3d(-0.5, 0, 0)));
  const CsgSolid b = CsgSolid::sphere(1.0).transformed(Iso3(Eigen::Translation3d(0.5, 0, 0)));
  const CsgSolid u = a | b;
  const CsgSolid lens = a & b;
  // Union: exact outside.
  const SdfSample far = u.evaluate(Vec3(3, 0, 0));
  EXPECT_NEAR(far.distance_m, 1.5, kTol);
  EXPECT_TRUE(far.exact);
  expect_sample(u, Vec3(0, 2, 0), std::sqrt(4.25) - 1.0, Vec3(0.5, 2, 0).normalized());
  // Union inside the overlap: sign right, magnitude a bound (true distance to the waist is √.75).
  const SdfSample mid = u.evaluate(Vec3::Zero());
  EXPECT_NEAR(mid.distance_m, -0.5, kTol);
  EXPECT_FALSE(mid.exact);
  EXPECT_LT(std::abs(mid.distance_m), std::sqrt(0.75));
  // Intersection (lens): exact inside, 0.5 from both surfaces at the centre.
  const SdfSample in = lens.evaluate(Vec3::Zero());
  EXPECT_NEAR(in.distance_m, -0.5, kTol);
  EXPECT_TRUE(in.exact);
  expect_distance(lens, Vec3(0, 0.8, 0), std::sqrt(0.25 + 0.64) - 1.0);
  EXPECT_FALSE(lens.contains(Vec3(0.6, 0, 0)));
  EXPECT_FALSE(lens.evaluate(Vec3(2, 0, 0)).exact);  // outside the lens: a bound
  EXPECT_NEAR(lens.distance(Vec3(2, 0, 0)), 1.5, kTol);  // true distance 1.5 to the tip (0.5,0,0)
  const Box3 region(Vec3(-2.5, -2, -2), Vec3(2.5, 2, 2));
  check_gradients(u, region);
  check_gradients(lens, region);
  check_distance_bound(u, region, Exact::kSomewhere);
  check_distance_bound(lens, region, Exact::kSomewhere);
  // Bounds: union merges, intersection intersects.
  EXPECT_NEAR(u.bounds().min().x(), -1.5, kTol);
  EXPECT_NEAR(u.bounds().max().x(), 1.5, kTol);
  EXPECT_NEAR(lens.bounds().min().x(), -0.5, kTol);
  EXPECT_NEAR(lens.bounds().max().x(), 0.5, kTol);
}

TEST(CsgTest, DeepTreeIsConservative) {
  // A bracket: plate ∪ boss, minus a through hole and a torus groove, plus a cone.
  const CsgSolid plate = CsgSolid::block(Vec3(0.04, 0.03, 0.005));
  const CsgSolid boss = CsgSolid::cylinder(0.015, 0.012);
  const CsgSolid hole = CsgSolid::cylinder(0.006, 0.05);
  const CsgSolid groove =
      CsgSolid::torus(0.015, 0.003).transformed(Iso3(Eigen::Translation3d(0, 0, 0.012)));
  const CsgSolid tip = CsgSolid::cone(0.01, 0.02).transformed(
      Eigen::Translation3d(0.03, 0, 0.005) * Eigen::AngleAxisd(0.2, Vec3::UnitY()));
  const CsgSolid part = ((plate | boss) - hole - groove) | tip;
  EXPECT_EQ(part.node_count(), 11U);
  const Box3 region(Vec3(-0.05, -0.04, -0.02), Vec3(0.05, 0.04, 0.03));
  check_gradients(part, region);
  // The top union is inexact inside, and its left child (a difference) inexact outside.
  check_distance_bound(part, region, Exact::kNowhere);
  EXPECT_FALSE(part.contains(Vec3::Zero()));              // in the hole
  EXPECT_TRUE(part.contains(Vec3(0.03, 0.02, 0)));        // in the plate
  expect_distance(part, Vec3(0.008, 0, 0), -0.002);       // hole wall 2 mm away, boss side 7 mm
}

TEST(CsgTest, EmptySolidIsUnionIdentity) {
  const CsgSolid empty;
  EXPECT_TRUE(empty.is_empty());
  EXPECT_EQ(empty.distance(Vec3::Zero()), kInf);
  EXPECT_TRUE(empty.bounds().isEmpty());
  const CsgSolid s = CsgSolid::sphere(1.0);
  EXPECT_EQ((empty | s).node_count(), 1U);
  EXPECT_TRUE((empty & s).is_empty());
  EXPECT_EQ((s - empty).node_count(), 1U);
  EXPECT_TRUE((empty - s).is_empty());
}

TEST(CsgTest, BadParametersThrow) {
  EXPECT_THROW(CsgSolid::sphere(0.0), Error);
  EXPECT_THROW(CsgSolid::sphere(-1.0), Error);
  EXPECT_THROW(CsgSolid::sphere(std::nan("")), Error);
  EXPECT_THROW(CsgSolid::block(Vec3(1, 0, 1)), Error);
  EXPECT_THROW(CsgSolid::cylinder(1.0, kInf), Error);
  EXPECT_THROW(CsgSolid::cone(1.0, 0.0), Error);
  EXPECT_THROW(CsgSolid::frustum(0.0, 0.0, 1.0), Error);
  EXPECT_THROW(CsgSolid::frustum(-1.0, 1.0, 1.0), Error);
  EXPECT_THROW(CsgSolid::torus(1.0, 1.5), Error);  // spindle torus
  Iso3 scaled = Iso3::Identity();
  scaled.linear() *= 2.0;
  EXPECT_THROW(CsgSolid::sphere(1.0).transformed(scaled), Error);
  Iso3 mirrored = Iso3::Identity();
  mirrored.linear()(0, 0) = -1.0;
  EXPECT_THROW(CsgSolid::sphere(1.0).transformed(mirrored), Error);
  try {
    CsgSolid::torus(1.0, -0.1);
    FAIL() << "expected hapsim::Error";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("torus minor radius"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace hapsim
