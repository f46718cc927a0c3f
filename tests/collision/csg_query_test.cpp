// CsgQuery against hand-computed answers: a cylinder with a spherical dimple cut into its top
// (cylinder minus sphere) and a torus, at points inside and outside, where the field is exact,
// where it is a bound that the query certifies, and near the dimple's rim where only the
// polygonised mesh can answer. Then against the mesh's own exact query (MeshBvh) everywhere
// around the solids, within the polygoniser's resolution, and contact_within allocating nothing.
#include "hapsim/collision/csg_query.h"

#include "hapsim/collision/mesh_bvh.h"
#include "hapsim/core/error.h"
#include "hapsim/geometry/polygonizer.h"

#include "support/allocation_counter.h"

#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <vector>

namespace hapsim {
namespace {

constexpr double kResolutionM = 0.001;

// Cylinder of radius 30 mm, z in [-20, 20] mm, minus a sphere of radius 15 mm centred on the
// top cap: a bowl-shaped dimple whose bottom is at z = 5 mm and whose rim is the circle
// ρ = 15 mm, z = 20 mm.
constexpr double kR = 0.03;
constexpr double kH = 0.02;
constexpr double kDimple = 0.015;

CsgSolid dimpled_cylinder() {
  return CsgSolid::cylinder(kR, kH) -
         CsgSolid::sphere(kDimple).transformed(Iso3(Eigen::Translation3d(0, 0, kH)));
}

// Torus in the xy plane: tube centre circle 30 mm, tube radius 10 mm.
constexpr double kMajor = 0.03;
constexpr double kMinor = 0.01;

TriangleMesh mesh_of(const CsgSolid& solid) {
  PolygonizeOptions o;
  o.cell_size_m = kResolutionM;
  return polygonize(solid, o);
}

struct Expected {
  const char* what;
  Vec3 p;
  double distance_m;
  Vec3 point;
  Vec3 normal;
  CsgAnswer how;
};

void expect_answers(const CsgQuery& q, const std::vector<Expected>& cases) {
  for (const Expected& e : cases) {
    SCOPED_TRACE(e.what);
    CsgAnswer how{};
    const SurfacePoint sp = q.closest_point_explained(e.p, nullptr, &how);
    EXPECT_EQ(how, e.how);
    EXPECT_NEAR(sp.signed_distance, e.distance_m, 1e-12);
    EXPECT_LT((sp.point - e.point).norm(), 1e-12) << sp.point.transpose();
    EXPECT_LT((sp.normal - e.normal).norm(), 1e-12) << sp.normal.transpose();
    EXPECT_EQ(sp.triangle, kSdfSurface);
    EXPECT_TRUE(sp.found());
    // The same answer through contact_within, inside its radius and not beyond it.
    SurfacePoint within;
    ASSERT_TRUE(q.contact_within(e.p, std::abs(e.distance_m) + 1e-6, &within));
    EXPECT_NEAR(within.signed_distance, e.distance_m, 1e-12);
    EXPECT_FALSE(q.contact_within(e.p, std::abs(e.distance_m) - 1e-6, &within));
  }
}

TEST(CsgQuery, CylinderMinusSphereMatchesAnalyticAnswers) {
  const CsgSolid solid = dimpled_cylinder();
  const TriangleMesh mesh = mesh_of(solid);
  const CsgQuery q(solid, mesh);
  const Vec3 top(0, 0, kH);  // the dimple's centre
  const double s = std::sqrt(0.5);
  expect_answers(
      q, {
             // Inside the solid under the dimple: 10 mm to its bottom (bottom cap 15, side 30 mm).
             {"inside, under the dimple", Vec3(0, 0, -0.005), -0.010, Vec3(0, 0, kH - kDimple),
              Vec3(0, 0, 1), CsgAnswer::kExactField},
             // Inside, nearest the side wall.
             {"inside, near the wall", Vec3(0.025, 0, -0.01), -0.005, Vec3(kR, 0, -0.01),
              Vec3(1, 0, 0), CsgAnswer::kExactField},
             // Inside the dimple (outside the solid): the bound r − |p − c| is certified, the
             // nearest point is on the dimple's face straight below.
             {"in the dimple", Vec3(0, 0, kH - 0.005), 0.010, Vec3(0, 0, kH - kDimple),
              Vec3(0, 0, 1), CsgAnswer::kCertified},
             // In the dimple, off-axis, along a 45° ray from its centre.
             {"in the dimple, off-axis", top + 0.005 * Vec3(s, 0, -s), 0.010,
              top + kDimple * Vec3(s, 0, -s), Vec3(-s, 0, s), CsgAnswer::kCertified},
             // Beside the cylinder and above its flat top ring.
             {"beside the wall", Vec3(0.05, 0, 0), 0.020, Vec3(kR, 0, 0), Vec3(1, 0, 0),
              CsgAnswer::kCertified},
             {"above the flat ring", Vec3(0, 0.025, kH + 0.01), 0.010, Vec3(0, 0.025, kH),
              Vec3(0, 0, 1), CsgAnswer::kCertified},
             // Outside the side and the bottom: the bottom rim edge (exact corner distance).
             {"beyond the bottom edge", Vec3(kR + 0.003, 0, -kH - 0.004), 0.005, Vec3(kR, 0, -kH),
              Vec3(0.6, 0, -0.8), CsgAnswer::kCertified},
         });
}

TEST(CsgQuery, AboveTheDimpleRimTheMeshAnswersWithinTheResolution) {
  // Above the dimple's centre the nearest surface is the rim circle, at
  // sqrt(15² + 20²) = 25 mm; the field's bound (20 mm, to the removed cap) cannot be certified.
  const CsgSolid solid = dimpled_cylinder();
  const TriangleMesh mesh = mesh_of(solid);
  const CsgQuery q(solid, mesh);
  const Vec3 p(0, 0, kH + 0.02);
  EXPECT_NEAR(solid.evaluate(p).distance_m, 0.02, 1e-12);
  EXPECT_FALSE(solid.evaluate(p).exact);
  CsgAnswer how{};
  const SurfacePoint sp = q.closest_point_explained(p, nullptr, &how);
  EXPECT_EQ(how, CsgAnswer::kMesh);
  EXPECT_NEAR(sp.signed_distance, 0.025, kResolutionM);
  EXPECT_NEAR(std::hypot(sp.point.x(), sp.point.y()), kDimple, kResolutionM);
  EXPECT_NEAR(sp.point.z(), kH, kResolutionM);
  EXPECT_LT(sp.triangle, mesh.triangles.size());
  SurfacePoint within;
  EXPECT_FALSE(q.contact_within(p, 0.015, &within));  // the bound alone says no
  EXPECT_TRUE(q.contact_within(p, 0.026, &within));
  EXPECT_NEAR(within.signed_distance, sp.signed_distance, 1e-12);
}

TEST(CsgQuery, TorusMatchesAnalyticAnswers) {
  const CsgSolid solid = CsgSolid::torus(kMajor, kMinor);
  const TriangleMesh mesh = mesh_of(solid);
  const CsgQuery q(solid, mesh);
  expect_answers(
      q, {
             {"outside, in the plane", Vec3(0.05, 0, 0), 0.010, Vec3(0.04, 0, 0), Vec3(1, 0, 0),
              CsgAnswer::kExactField},
             {"in the hole", Vec3(0, 0.01, 0), 0.010, Vec3(0, 0.02, 0), Vec3(0, -1, 0),
              CsgAnswer::kExactField},
             {"inside the tube", Vec3(0, 0.03, 0.005), -0.005, Vec3(0, 0.03, 0.01), Vec3(0, 0, 1),
              CsgAnswer::kExactField},
             // (ρ − R, z) = (15, 20) mm: 25 mm from the tube's centre, 15 mm from its surface.
             {"above and beyond", Vec3(0, -0.045, 0.02), 0.015, Vec3(0, -0.036, 0.008),
              Vec3(0, -0.6, 0.8), CsgAnswer::kExactField},
         });
}

// The query and the polygonised mesh's exact BVH agree everywhere around the solid to within
// the polygoniser's resolution (its vertices are on the surface; edges are bevelled by about a
// cell), and contact_within agrees with closest_point.
void expect_agrees_with_mesh(const CsgSolid& solid) {
  const TriangleMesh mesh = mesh_of(solid);
  const CsgQuery q(solid, mesh);
  const MeshBvh bvh(mesh);
  const Box3 box = solid.bounds();
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  int certified = 0;
  int from_mesh = 0;
  for (int i = 0; i < 3000; ++i) {
    const Vec3 t(u(rng), u(rng), u(rng));
    const Vec3 p =
        box.min() - Vec3::Constant(0.01) + t.cwiseProduct(box.sizes() + Vec3::Constant(0.02));
    CsgAnswer how{};
    const SurfacePoint a = q.closest_point_explained(p, nullptr, &how);
    const SurfacePoint b = bvh.closest_point(p);
    certified += how == CsgAnswer::kCertified ? 1 : 0;
    from_mesh += how == CsgAnswer::kMesh ? 1 : 0;
    ASSERT_NEAR(a.signed_distance, b.signed_distance, kResolutionM) << p.transpose();
    ASSERT_NEAR(a.normal.norm(), 1.0, 1e-9);
    // The field's answers are exact: the point is on the surface, |p − point| = |d|.
    if (how != CsgAnswer::kMesh) {
      ASSERT_NEAR(solid.distance(a.point), 0.0, 1e-12) << p.transpose();
      ASSERT_NEAR((p - a.point).norm(), std::abs(a.signed_distance), 1e-12);
    }
    const double radius = 0.004;
    SurfacePoint w;
    const bool near = q.contact_within(p, radius, &w);
    if (std::abs(std::abs(a.signed_distance) - radius) > 1e-9) {
      ASSERT_EQ(near, std::abs(a.signed_distance) <= radius) << p.transpose();
    }
    if (near) {
      ASSERT_NEAR(w.signed_distance, a.signed_distance, 1e-12);
    }
  }
  ::testing::Test::RecordProperty("certified", certified);
  ::testing::Test::RecordProperty("from_mesh", from_mesh);
}

TEST(CsgQuery, CylinderMinusSphereAgreesWithItsMesh) {
  expect_agrees_with_mesh(dimpled_cylinder());
}

TEST(CsgQuery, TorusAgreesWithItsMesh) {
  expect_agrees_with_mesh(
      CsgSolid::torus(kMajor, kMinor)
          .transformed(Iso3(Eigen::AngleAxisd(0.7, Vec3(1, 1, 0).normalized()))));
}

TEST(CsgQuery, ContactWithinAllocatesNothing) {
  // A union of two overlapping blocks minus a sphere: points where the field is exact, where a
  // bound is certified and where the mesh answers (inside both blocks, at the rim).
  const CsgSolid solid =
      (CsgSolid::block(Vec3(0.02, 0.01, 0.01)) |
       CsgSolid::block(Vec3(0.01, 0.02, 0.01))
           .transformed(Iso3(Eigen::Translation3d(0.005, 0, 0)))) -
      CsgSolid::sphere(0.008).transformed(Iso3(Eigen::Translation3d(0, 0, 0.01)));
  const TriangleMesh mesh = mesh_of(solid);
  const CsgQuery q(solid, mesh);
  std::vector<Vec3> points;
  for (int i = -12; i <= 12; ++i) {
    for (int k = -6; k <= 6; ++k) {
      points.emplace_back(0.002 * i, 0.001 * i, 0.002 * k);
    }
  }
  SurfacePoint sp;
  QueryHint hint;
  int answered = 0;
  const long before = test::allocation_count();
  for (const Vec3& p : points) {
    answered += q.contact_within(p, 0.01, &sp, &hint) ? 1 : 0;
  }
  const long after = test::allocation_count();
  EXPECT_EQ(after, before);
  EXPECT_GT(answered, 0);
  // And the points did cover all three ways of answering.
  bool seen[3] = {false, false, false};
  for (const Vec3& p : points) {
    CsgAnswer how{};
    (void)q.closest_point_explained(p, nullptr, &how);
    seen[static_cast<int>(how)] = true;
  }
  EXPECT_TRUE(seen[0] && seen[1] && seen[2]);
}

TEST(CsgQuery, RefusesAnEmptySolidOrMesh) {
  const TriangleMesh mesh = mesh_of(CsgSolid::sphere(0.01));
  EXPECT_THROW(CsgQuery(CsgSolid(), mesh), Error);
  EXPECT_THROW(CsgQuery(CsgSolid::sphere(0.01), TriangleMesh()), Error);
  const CsgQuery q(CsgSolid::sphere(0.01), mesh);
  EXPECT_EQ(q.method_name(), "csg");
  EXPECT_GT(q.memory_bytes(), q.mesh_query().memory_bytes());
}

}  // namespace
}  // namespace hapsim
