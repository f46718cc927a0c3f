// Mass properties of closed meshes against the textbook formulas: a box (V = abc, I = m/12·(b²+c²)
// …) placed off the origin, and a finely tessellated sphere (V → 4/3πr³, I → 2/5·m·r²).
#include "hapsim/geometry/mass_properties.h"

#include "hapsim/core/error.h"
#include "hapsim/geometry/procedural.h"

#include <gtest/gtest.h>

#include <numbers>

namespace hapsim {
namespace {

TEST(MassProperties, BoxMatchesTheTextbook) {
  const Vec3 half(0.1, 0.2, 0.3);
  TriangleMesh mesh = make_box(half);
  const Vec3 offset(1.0, -2.0, 0.5);
  for (Vec3& v : mesh.vertices) {
    v += offset;
  }
  const MassProperties m = mass_properties(mesh);
  const Vec3 s = 2.0 * half;
  const double v = s.prod();
  EXPECT_NEAR(m.volume_m3, v, 1e-12);
  EXPECT_LT((m.com - offset).norm(), 1e-12);
  const Mat3 expected =
      Vec3(v / 12.0 * (s.y() * s.y() + s.z() * s.z()), v / 12.0 * (s.x() * s.x() + s.z() * s.z()),
           v / 12.0 * (s.x() * s.x() + s.y() * s.y()))
          .asDiagonal();
  EXPECT_LT((m.inertia_per_density - expected).norm(), 1e-12);
}

TEST(MassProperties, FineSphereApproachesTheBall) {
  const double r = 0.03;
  const MassProperties m = mass_properties(make_uv_sphere(r, 256, 128));
  const double v = 4.0 / 3.0 * std::numbers::pi * r * r * r;
  EXPECT_NEAR(m.volume_m3 / v, 1.0, 1e-3);
  EXPECT_LT(m.com.norm(), 1e-12);
  const double i = 0.4 * v * r * r;
  for (int k = 0; k < 3; ++k) {
    EXPECT_NEAR(m.inertia_per_density(k, k) / i, 1.0, 2e-3);
  }
  EXPECT_NEAR(m.inertia_per_density(0, 1), 0.0, 1e-15);
}

TEST(MassProperties, OpenOrInsideOutMeshIsRefused) {
  TriangleMesh mesh = make_box(Vec3(0.1, 0.1, 0.1));
  for (TriangleIndices& t : mesh.triangles) {
    std::swap(t[1], t[2]);
  }
  EXPECT_THROW((void)mass_properties(mesh), Error);
  EXPECT_THROW((void)mass_properties(make_sheet(4, 0.1)), Error);
}

}  // namespace
}  // namespace hapsim
