#include "hapsim/deform/virtual_sheet.h"

#include "hapsim/core/error.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <memory>
#include <vector>

namespace hapsim {
namespace {

// The paper's formula written out independently, in the paper's units (mm, N, N/mm); returns the
// downward displacement in millimetres.
double paper_displacement_mm(double d_mm, double force_n) {
  const double d0_mm = 44.0, xi_mm = 40.1, f0_n_per_mm = 3.0;
  if (d_mm >= d0_mm) {
    return 0.0;
  }
  return force_n / f0_n_per_mm *
         (std::exp(-(d_mm / xi_mm) * (d_mm / xi_mm)) -
          std::exp(-(d0_mm / xi_mm) * (d0_mm / xi_mm)));
}

Vec3 node_xy(const VirtualSheet& sheet, int i, int j) {
  const double half = 0.5 * sheet.side_m();
  return Vec3(-half + i * sheet.spacing_m(), -half + j * sheet.spacing_m(), 0.0);
}

TEST(VirtualSheet, DefaultsAre16By16AndFlat) {
  VirtualSheet sheet;
  EXPECT_EQ(sheet.nodes_per_side(), 16);
  EXPECT_EQ(sheet.mesh().vertex_count(), 256u);
  EXPECT_EQ(sheet.mesh().triangle_count(), 2u * 15u * 15u);
  for (const Vec3& v : sheet.mesh().vertices) {
    EXPECT_EQ(v.z(), 0.0);
  }
  EXPECT_EQ(sheet.max_depth_m(), 0.0);
}

TEST(VirtualSheet, MatchesPaperFormulaAtEveryNode) {
  VirtualSheet sheet;
  const Vec3 p(0.011, -0.004, 0.0);  // off-node on purpose
  const double force_n = 2.5;
  const SheetContact contact{p, force_n};
  sheet.apply_contacts({&contact, 1});
  int nonzero = 0;
  for (int j = 0; j < 16; ++j) {
    for (int i = 0; i < 16; ++i) {
      const Vec3 q = node_xy(sheet, i, j);
      const double d_mm = 1e3 * std::hypot(q.x() - p.x(), q.y() - p.y());
      const double expected_m = -1e-3 * paper_displacement_mm(d_mm, force_n);
      const double z = sheet.mesh().vertices[static_cast<std::size_t>(j * 16 + i)].z();
      EXPECT_NEAR(z, expected_m, 1e-15) << "node " << i << "," << j;
      if (d_mm >= 44.0) {
        EXPECT_EQ(z, 0.0) << "node beyond d0 moved: " << i << "," << j;
      } else {
        ++nonzero;
      }
    }
  }
  EXPECT_GT(nonzero, 10);  // the check above actually covered displaced nodes
}

TEST(VirtualSheet, UnitsThreeNewtonsGiveSevenTenthsOfAMillimetre) {
  // F/F0 = 3 N / 3 N/mm = 1 mm; 1 − e^{−(44/40.1)²} = 0.69997… so the node under the force sinks
  // 0.700 mm = 7.0e-4 m. Catches a mm/m slip by a factor 1000.
  VirtualSheet sheet;
  const SheetContact c{node_xy(sheet, 7, 7), 3.0};
  sheet.apply_contacts({&c, 1});
  EXPECT_NEAR(sheet.surface_heights()[7 * 16 + 7], -7.0e-4, 1e-6);
  EXPECT_NEAR(sheet.max_depth_m(), 7.0e-4, 1e-6);
  EXPECT_NEAR(sheet.height_at(c.p_sheet.x(), c.p_sheet.y()), -7.0e-4, 1e-6);
}

TEST(VirtualSheet, TwoContactsSum) {
  VirtualSheet sheet;
  const SheetContact a{Vec3(-0.02, 0.0, 0.0), 3.0};
  const SheetContact b{Vec3(0.015, 0.01, 0.0), 1.5};
  sheet.apply_contacts({&a, 1});
  const std::vector<double> za(sheet.surface_heights().begin(), sheet.surface_heights().end());
  sheet.apply_contacts({&b, 1});
  const std::vector<double> zb(sheet.surface_heights().begin(), sheet.surface_heights().end());
  const std::vector<SheetContact> both{a, b};
  sheet.apply_contacts(both);
  int overlap = 0;
  for (std::size_t v = 0; v < za.size(); ++v) {
    EXPECT_NEAR(sheet.surface_heights()[v], za[v] + zb[v], 1e-15);
    overlap += (za[v] < 0.0 && zb[v] < 0.0) ? 1 : 0;
  }
  EXPECT_GT(overlap, 0);  // the two bowls overlap, so summing is really exercised
}

TEST(VirtualSheet, EachCycleReplacesThePrevious) {
  VirtualSheet sheet;
  const SheetContact a{Vec3(0.0, 0.0, 0.0), 3.0};
  sheet.apply_contacts({&a, 1});
  EXPECT_GT(sheet.max_depth_m(), 0.0);
  sheet.apply_contacts({});
  EXPECT_EQ(sheet.max_depth_m(), 0.0);
}

class ConeProfile final : public SheetProfile {
 public:
  double depth_m(double d, double f) const override {
    return d < 0.03 ? f * 1e-3 * (1 - d / 0.03) : 0.0;
  }
  double influence_radius_m() const override { return 0.03; }
};

TEST(VirtualSheet, ProfileIsReplaceable) {
  VirtualSheet sheet({}, std::make_unique<ConeProfile>());
  const Vec3 p = node_xy(sheet, 7, 7);
  const SheetContact c{p, 2.0};
  sheet.apply_contacts({&c, 1});
  EXPECT_NEAR(sheet.surface_heights()[7 * 16 + 7], -2e-3, 1e-15);
  const double d = sheet.spacing_m();
  EXPECT_NEAR(sheet.surface_heights()[7 * 16 + 8], -2e-3 * (1 - d / 0.03), 1e-15);
  EXPECT_EQ(sheet.surface_heights()[7 * 16 + 11], 0.0);  // 4 spacings = 53 mm > 30 mm
}

TEST(VirtualSheet, ImprintMatchesSphereCap) {
  VirtualSheet sheet;
  const Vec3 c(0.004, 0.002, 0.015);
  const double r = 0.03;
  sheet.imprint_sphere(c, r);
  int lowered = 0;
  for (int j = 0; j < 16; ++j) {
    for (int i = 0; i < 16; ++i) {
      const Vec3 q = node_xy(sheet, i, j);
      const double d2 = (q.x() - c.x()) * (q.x() - c.x()) + (q.y() - c.y()) * (q.y() - c.y());
      const double cap = d2 < r * r ? c.z() - std::sqrt(r * r - d2) : kInf;
      const double expected = std::min(0.0, cap);
      EXPECT_NEAR(sheet.mesh().vertices[static_cast<std::size_t>(j * 16 + i)].z(), expected, 1e-15);
      lowered += expected < 0.0 ? 1 : 0;
    }
  }
  EXPECT_GT(lowered, 3);
  // The elastic field is untouched by the imprint.
  for (double z : sheet.elastic_heights()) {
    EXPECT_EQ(z, 0.0);
  }
}

TEST(VirtualSheet, ImprintCombinesWithForceAsMinimum) {
  VirtualSheet sheet;
  const Vec3 c(0.0, 0.0, 0.02);
  const double r = 0.021;  // cap bottom 1 mm below rest
  const SheetContact contact{Vec3(0.0, 0.0, 0.0), 3.0};
  sheet.apply_contacts({&contact, 1});
  sheet.imprint_sphere(c, r);
  for (std::size_t v = 0; v < 256; ++v) {
    const Vec3 q = sheet.mesh().vertices[v];
    const double d2 = q.x() * q.x() + q.y() * q.y();
    const double cap = d2 < r * r ? c.z() - std::sqrt(r * r - d2) : kInf;
    EXPECT_DOUBLE_EQ(q.z(), std::min(sheet.elastic_heights()[v], cap));
  }
  // A sphere above the sheet leaves it alone.
  const std::vector<double> before(sheet.surface_heights().begin(), sheet.surface_heights().end());
  sheet.imprint_sphere(Vec3(0.0, 0.0, 0.05), 0.02);
  EXPECT_TRUE(std::equal(before.begin(), before.end(), sheet.surface_heights().begin()));
}

TEST(VirtualSheet, HeightAndNormalInterpolateTheMesh) {
  VirtualSheet sheet;
  const SheetContact contact{Vec3(0.003, 0.001, 0.0), 3.0};
  sheet.apply_contacts({&contact, 1});
  // At nodes, height equals the node; inside a triangle, it lies on the triangle's plane.
  EXPECT_DOUBLE_EQ(sheet.height_at(node_xy(sheet, 8, 7).x(), node_xy(sheet, 8, 7).y()),
                   sheet.surface_heights()[7 * 16 + 8]);
  const TriangleMesh& m = sheet.mesh();
  for (std::size_t t = 0; t < m.triangle_count(); t += 7) {
    const auto c = m.corners(t);
    const Vec3 centroid = (c[0] + c[1] + c[2]) / 3.0;
    EXPECT_NEAR(sheet.height_at(centroid.x(), centroid.y()), centroid.z(), 1e-15);
    const Vec3 n = sheet.normal_at(centroid.x(), centroid.y());
    EXPECT_NEAR((n - m.face_normal(t)).norm(), 0.0, 1e-12) << "triangle " << t;
  }
  // A bowl: on its rim the normal leans towards the dent's axis (left of it, towards +x).
  EXPECT_GT(sheet.normal_at(-0.01, 0.0).x(), 0.0);
  EXPECT_LT(sheet.normal_at(0.02, 0.0).x(), 0.0);
}

TEST(VirtualSheet, SphereContactOnFlatSheet) {
  VirtualSheet sheet;
  const SheetSphereContact c = sheet.sphere_contact(Vec3(0.001, 0.002, 0.008), 0.01);
  ASSERT_TRUE(c.touching);
  EXPECT_NEAR(c.penetration_m, 0.002, 1e-12);
  EXPECT_NEAR((c.normal_sheet - Vec3::UnitZ()).norm(), 0.0, 1e-12);
  EXPECT_FALSE(sheet.sphere_contact(Vec3(0.0, 0.0, 0.0101), 0.01).touching);
  // Passed through: centre 3 mm below the sheet.
  const SheetSphereContact below = sheet.sphere_contact(Vec3(0.0, 0.0, -0.003), 0.01);
  ASSERT_TRUE(below.touching);
  EXPECT_NEAR(below.penetration_m, 0.013, 1e-12);
  EXPECT_NEAR((below.normal_sheet - Vec3::UnitZ()).norm(), 0.0, 1e-12);
  // Off the square: nothing.
  EXPECT_FALSE(sheet.sphere_contact(Vec3(0.5, 0.0, 0.0), 0.01).touching);
}

TEST(VirtualSheet, SphereContactSeesElasticOrSurface) {
  // Fine grid (1.56 mm): the imprint then follows the sphere closely between nodes too; on the
  // default 13 mm grid the triangles between imprinted nodes are chords that still cut the sphere.
  VirtualSheet sheet({.nodes_per_side = 129});
  const SheetContact force{Vec3::Zero(), 3.0};
  sheet.apply_contacts({&force, 1});
  const double dent_m = -sheet.height_at(0.0, 0.0);
  ASSERT_GT(dent_m, 1e-4);
  const Vec3 center(0.0, 0.0, 0.01 - dent_m - 0.0005);  // 0.5 mm into the dented sheet
  const SheetSphereContact e = sheet.sphere_contact(center, 0.01, SheetLayer::kElastic);
  ASSERT_TRUE(e.touching);
  EXPECT_NEAR(e.penetration_m, 0.0005, 5e-5);  // curved bowl: slightly less than vertical gap
  EXPECT_GT(e.normal_sheet.z(), 0.99);
  sheet.imprint_sphere(center, 0.01);
  // Against its own imprint the sphere barely touches (chord sagitta only); against the elastic
  // field it still does.
  EXPECT_LT(sheet.sphere_contact(center, 0.01, SheetLayer::kSurface).penetration_m, 1e-4);
  EXPECT_NEAR(sheet.sphere_contact(center, 0.01, SheetLayer::kElastic).penetration_m,
              e.penetration_m, 1e-15);
}

TEST(VirtualSheet, ResetFlattens) {
  VirtualSheet sheet;
  const SheetContact force{Vec3::Zero(), 3.0};
  sheet.apply_contacts({&force, 1});
  sheet.imprint_sphere(Vec3(0.03, 0.0, 0.005), 0.01);
  sheet.reset();
  for (const Vec3& v : sheet.mesh().vertices) {
    EXPECT_EQ(v.z(), 0.0);
  }
  for (const Vec3& n : sheet.mesh().vertex_normals) {
    EXPECT_EQ(n, Vec3::UnitZ());
  }
}

TEST(VirtualSheet, NoAllocationOrMovingBuffersPerCycle) {
  VirtualSheet sheet;
  const TriangleMesh* mesh = &sheet.mesh();
  const Vec3* vertices = sheet.mesh().vertices.data();
  const Vec3* normals = sheet.mesh().vertex_normals.data();
  const double* heights = sheet.surface_heights().data();
  std::vector<SheetContact> contacts{{Vec3(0.01, 0.0, 0.0), 2.0}, {Vec3(-0.02, 0.03, 0.0), 1.0}};
  for (int k = 0; k < 100; ++k) {
    contacts[0].p_sheet.x() = 0.001 * k - 0.05;
    sheet.apply_contacts(contacts);
    sheet.imprint_sphere(Vec3(0.0, 0.001 * k - 0.05, 0.01), 0.012);
    (void)sheet.sphere_contact(Vec3(0.0, 0.0, 0.005), 0.01);
  }
  EXPECT_EQ(&sheet.mesh(), mesh);
  EXPECT_EQ(sheet.mesh().vertices.data(), vertices);
  EXPECT_EQ(sheet.mesh().vertex_normals.data(), normals);
  EXPECT_EQ(sheet.surface_heights().data(), heights);
  // The mesh address survives a move of the sheet (collision structures may hold it).
  VirtualSheet moved = std::move(sheet);
  EXPECT_EQ(&moved.mesh(), mesh);
}

TEST(VirtualSheet, BadParametersThrow) {
  EXPECT_THROW(VirtualSheet({.nodes_per_side = 1}), Error);
  EXPECT_THROW(VirtualSheet({.side_m = -0.1}), Error);
  EXPECT_THROW(VirtualSheet({.side_m = std::numeric_limits<double>::quiet_NaN()}), Error);
  EXPECT_THROW(VirtualSheet({.max_depth_m = 0.0}), Error);
  EXPECT_THROW(GaussianSheetProfile({.cutoff_radius_m = -0.044}), Error);
  EXPECT_THROW(GaussianSheetProfile({.sensitivity_n_per_m = 0.0}), Error);
  EXPECT_THROW(GaussianSheetProfile({.width_m = std::numeric_limits<double>::infinity()}), Error);
  EXPECT_NO_THROW(VirtualSheet({.nodes_per_side = 2}));
}

TEST(VirtualSheet, BadContactsNeverGiveNaN) {
  VirtualSheet sheet;
  const double nan = std::numeric_limits<double>::quiet_NaN();
  const double inf = std::numeric_limits<double>::infinity();
  const std::vector<SheetContact> contacts{{Vec3(0.0, 0.0, 0.0), nan},
                                           {Vec3(nan, 0.0, 0.0), 1.0},
                                           {Vec3(0.0, 0.0, 0.0), inf},
                                           {Vec3(0.01, 0.0, 0.0), -5.0},  // pulls: clamped to 0
                                           {Vec3(1e300, -1e300, 0.0), 1.0}};
  sheet.apply_contacts(contacts);
  sheet.imprint_sphere(Vec3(nan, 0.0, 0.0), 0.01);
  sheet.imprint_sphere(Vec3(0.0, 0.0, 0.0), -0.01);
  EXPECT_EQ(sheet.rejected_contacts(), 5u);
  for (const Vec3& v : sheet.mesh().vertices) {
    EXPECT_EQ(v.z(), 0.0);
  }
  EXPECT_FALSE(sheet.sphere_contact(Vec3(nan, 0.0, 0.0), 0.01).touching);
  EXPECT_TRUE(std::isfinite(sheet.height_at(nan, 0.0)));
  EXPECT_TRUE(sheet.normal_at(nan, inf).allFinite());
}

TEST(VirtualSheet, MaxDepthClampsHugeForces) {
  VirtualSheet sheet({.max_depth_m = 0.01});
  const SheetContact c{Vec3::Zero(), 1e6};
  sheet.apply_contacts({&c, 1});
  EXPECT_NEAR(sheet.max_depth_m(), 0.01, 1e-15);
  for (const Vec3& n : sheet.mesh().vertex_normals) {
    EXPECT_TRUE(n.allFinite());
  }
}

}  // namespace
}  // namespace hapsim
