// TriangleMesh and the procedural meshes against analytic geometry.
#include "hapsim/geometry/triangle_mesh.h"
#include "hapsim/geometry/mesh_validation.h"
#include "hapsim/geometry/procedural.h"

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

namespace hapsim {
namespace {

constexpr double kPi = std::numbers::pi;

// Every face normal points away from the (convex, centred) body's centre.
void expect_outward(const TriangleMesh& mesh, const Vec3& centre = Vec3::Zero()) {
  for (std::size_t t = 0; t < mesh.triangle_count(); ++t) {
    const auto [a, b, c] = mesh.corners(t);
    const Vec3 centroid = (a + b + c) / 3.0;
    EXPECT_GT(mesh.face_normal(t).dot(centroid - centre), 0.0) << "triangle " << t;
  }
}

void expect_clean_closed(const TriangleMesh& mesh) {
  const MeshReport r = validate_mesh(mesh);
  EXPECT_TRUE(r.closed) << r.summary();
  EXPECT_FALSE(r.has_defects()) << r.summary();
  EXPECT_EQ(r.components, 1u);
  EXPECT_EQ(r.euler_characteristic, 2);
}

TEST(TriangleMesh, BoxVolumeAreaBoundsAndOrientation) {
  const Vec3 half(0.1, 0.2, 0.3);
  const TriangleMesh box = make_box(half);
  EXPECT_EQ(box.vertex_count(), 8u);
  EXPECT_EQ(box.triangle_count(), 12u);
  EXPECT_NEAR(box.signed_volume(), 8.0 * 0.1 * 0.2 * 0.3, 1e-15);
  EXPECT_NEAR(box.surface_area(), 8.0 * (0.1 * 0.2 + 0.2 * 0.3 + 0.1 * 0.3), 1e-14);
  EXPECT_TRUE(box.bounds().min().isApprox(-half));
  EXPECT_TRUE(box.bounds().max().isApprox(half));
  expect_outward(box);
  expect_clean_closed(box);
  // Angle-weighted normals at a box corner point along the corner diagonal.
  ASSERT_EQ(box.vertex_normals.size(), 8u);
  for (std::size_t v = 0; v < 8; ++v) {
    EXPECT_NEAR(box.vertex_normals[v].norm(), 1.0, 1e-12);
    EXPECT_TRUE(
        box.vertex_normals[v].isApprox(box.vertices[v].cwiseSign() / std::sqrt(3.0), 1e-12));
  }
}

TEST(TriangleMesh, UvSphereConvergesToAnalyticVolumeAndArea) {
  const double r = 0.05;
  double previous_error = kInf;
  for (int n : {16, 32, 64, 128}) {
    const TriangleMesh s = make_uv_sphere(r, 2 * n, n);
    EXPECT_EQ(s.triangle_count(), static_cast<std::size_t>(2 * (2 * n) * (n - 1)));
    const double volume = 4.0 / 3.0 * kPi * r * r * r;
    const double area = 4.0 * kPi * r * r;
    // Inscribed polyhedron: slightly less than the sphere, error O(1/n²).
    EXPECT_LT(s.signed_volume(), volume);
    EXPECT_LT(s.surface_area(), area);
    const double error = (volume - s.signed_volume()) / volume;
    EXPECT_LT(error, 5.0 / (n * n));
    EXPECT_LT(error, previous_error);
    previous_error = error;
    EXPECT_NEAR(s.surface_area(), area, area * 4.0 / (n * n));
    expect_outward(s);
    expect_clean_closed(s);
  }
  // Vertex normals of a sphere are radial.
  const TriangleMesh s = make_uv_sphere(r, 64, 32);
  for (std::size_t v = 0; v < s.vertex_count(); ++v) {
    EXPECT_GT(s.vertex_normals[v].dot(s.vertices[v].normalized()), 0.999);
  }
}

TEST(TriangleMesh, BumpySphereIsClosedNearTargetSize) {
  const TriangleMesh s = make_bumpy_sphere(20000);
  EXPECT_NEAR(static_cast<double>(s.triangle_count()), 20000.0, 2000.0);
  expect_clean_closed(s);
  EXPECT_GT(s.signed_volume(), 0.0);
}

TEST(TriangleMesh, SheetIsOpenWithUpNormals) {
  const int n = 16;
  const TriangleMesh sheet = make_sheet(n, 0.2);
  EXPECT_EQ(sheet.triangle_count(), static_cast<std::size_t>(2 * (n - 1) * (n - 1)));
  EXPECT_NEAR(sheet.surface_area(), 0.04, 1e-12);
  const MeshReport r = validate_mesh(sheet);
  EXPECT_FALSE(r.closed);
  EXPECT_EQ(r.open_edges, static_cast<std::size_t>(4 * (n - 1)));
  EXPECT_EQ(r.non_manifold_edges, 0u);
  EXPECT_EQ(r.inconsistent_edges, 0u);
  EXPECT_EQ(r.euler_characteristic, 1);  // a disc
  for (std::size_t t = 0; t < sheet.triangle_count(); ++t) {
    EXPECT_TRUE(sheet.face_normal(t).isApprox(Vec3::UnitZ()));
  }
  for (const Vec3& nrm : sheet.vertex_normals) {
    EXPECT_TRUE(nrm.isApprox(Vec3::UnitZ()));
  }
}

TEST(TriangleMesh, TransformKeepsVolumeAndMovesBounds) {
  TriangleMesh box = make_box(Vec3(0.1, 0.1, 0.1));
  Iso3 X = Iso3::Identity();
  X.linear() = Eigen::AngleAxisd(0.7, Vec3(1, 2, 3).normalized()).toRotationMatrix();
  X.translation() = Vec3(1.0, -2.0, 0.5);
  const Vec3 n0 = box.vertex_normals[3];
  box.transform(X);
  EXPECT_NEAR(box.signed_volume(), 0.008, 1e-12);
  EXPECT_TRUE(box.bounds().center().isApprox(X.translation(), 1e-12));
  EXPECT_TRUE(box.vertex_normals[3].isApprox(X.linear() * n0, 1e-12));
  expect_outward(box, X.translation());
}

TEST(TriangleMesh, ScaleScalesVolumeAndMirrorKeepsOutward) {
  TriangleMesh box = make_box(Vec3(10, 20, 30));  // "millimetres"
  box.scale(1e-3);
  EXPECT_NEAR(box.signed_volume(), 8 * 10 * 20 * 30 * 1e-9, 1e-15);
  TriangleMesh mirrored = make_box(Vec3(1, 2, 3));
  mirrored.scale(-2.0);
  EXPECT_NEAR(mirrored.signed_volume(), 8 * 6 * 8.0, 1e-9);
  expect_outward(mirrored);
  for (std::size_t v = 0; v < mirrored.vertex_count(); ++v) {
    EXPECT_GT(mirrored.vertex_normals[v].dot(mirrored.vertices[v]), 0.0);
  }
}

TEST(TriangleMesh, AppendOffsetsIndicesAndRecomputesNormals) {
  TriangleMesh a = make_box(Vec3(0.1, 0.1, 0.1));
  TriangleMesh b = make_uv_sphere(0.05, 16, 8);
  b.transform(Iso3(Eigen::Translation3d(1.0, 0.0, 0.0)));
  const double va = a.signed_volume();
  const double vb = b.signed_volume();
  const std::size_t na = a.vertex_count();
  a.append(b);
  EXPECT_EQ(a.vertex_count(), na + b.vertex_count());
  EXPECT_EQ(a.triangle_count(), 12 + b.triangle_count());
  EXPECT_NEAR(a.signed_volume(), va + vb, 1e-12);
  EXPECT_EQ(a.vertex_normals.size(), a.vertex_count());
  const MeshReport r = validate_mesh(a);
  EXPECT_TRUE(r.closed);
  EXPECT_EQ(r.components, 2u);
  EXPECT_EQ(r.euler_characteristic, 4);
  EXPECT_FALSE(r.has_defects()) << r.summary();
}

TEST(TriangleMesh, RemoveUnusedVerticesRenumbers) {
  TriangleMesh box = make_box(Vec3(0.1, 0.2, 0.3));
  const double volume = box.signed_volume();
  box.vertices.insert(box.vertices.begin(), Vec3(9, 9, 9));  // stray vertex at index 0
  box.vertices.push_back(Vec3(8, 8, 8));
  for (TriangleIndices& t : box.triangles) {
    for (auto& v : t) {
      ++v;
    }
  }
  box.compute_vertex_normals();
  EXPECT_EQ(validate_mesh(box).unused_vertices, 2u);
  EXPECT_EQ(box.remove_unused_vertices(), 2u);
  EXPECT_EQ(box.vertex_count(), 8u);
  EXPECT_EQ(box.vertex_normals.size(), 8u);
  EXPECT_NEAR(box.signed_volume(), volume, 1e-15);
  expect_clean_closed(box);
  EXPECT_EQ(box.remove_unused_vertices(), 0u);
}

TEST(TriangleMesh, DegenerateFaceHasZeroNormal) {
  TriangleMesh m;
  m.vertices = {Vec3(0, 0, 0), Vec3(1, 0, 0), Vec3(2, 0, 0)};
  m.triangles = {{0, 1, 2}};
  EXPECT_TRUE(m.face_normal(0).isZero());
  m.compute_vertex_normals();
  for (const Vec3& n : m.vertex_normals) {
    EXPECT_TRUE(n.isZero());
    EXPECT_FALSE(n.hasNaN());
  }
}

}  // namespace
}  // namespace hapsim
