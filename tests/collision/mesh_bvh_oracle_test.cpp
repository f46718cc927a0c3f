// MeshBvh against CGAL's AABB_tree: closest point and distance to 1e-9 relative on every test
// mesh, the real knee STLs included when the shared data folder is present.
#include "hapsim/collision/mesh_bvh.h"
#include "hapsim/core/data_dir.h"
#include "hapsim/geometry/procedural.h"
#include "oracles/closest_point_oracle.h"
#include "support/test_data.h"

#include <assimp/postprocess.h>
#include <assimp/scene.h>
#include <gtest/gtest.h>
#include <assimp/Importer.hpp>

#include <filesystem>
#include <random>
#include <string>

namespace hapsim {
namespace {

// Minimal loader (all meshes of the file, identical vertices welded), kept local so this test
// does not depend on the mesh IO module.
TriangleMesh load_stl(const std::filesystem::path& path) {
  Assimp::Importer importer;
  const aiScene* scene =
      importer.ReadFile(path.string(), aiProcess_Triangulate | aiProcess_JoinIdenticalVertices);
  TriangleMesh mesh;
  if (scene == nullptr) {
    return mesh;
  }
  for (unsigned m = 0; m < scene->mNumMeshes; ++m) {
    const aiMesh* am = scene->mMeshes[m];
    const auto base = static_cast<std::uint32_t>(mesh.vertices.size());
    for (unsigned v = 0; v < am->mNumVertices; ++v) {
      // STL files of the knee are in millimetres.
      const aiVector3D& p_mm = am->mVertices[v];
      mesh.vertices.emplace_back(1e-3 * static_cast<double>(p_mm.x),
                                 1e-3 * static_cast<double>(p_mm.y),
                                 1e-3 * static_cast<double>(p_mm.z));
    }
    for (unsigned f = 0; f < am->mNumFaces; ++f) {
      if (am->mFaces[f].mNumIndices == 3) {
        mesh.triangles.push_back({base + am->mFaces[f].mIndices[0],
                                  base + am->mFaces[f].mIndices[1],
                                  base + am->mFaces[f].mIndices[2]});
      }
    }
  }
  return mesh;
}

// Random points: half near the surface (on a triangle, pushed off by ~1% of the size), half
// anywhere in twice the bounding box.
std::vector<Vec3> sample_points(const TriangleMesh& mesh, int count, std::uint64_t seed) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  const Box3 box = mesh.bounds();
  const double size = box.diagonal().norm();
  std::normal_distribution<double> g(0.0, 0.01 * size);
  std::uniform_int_distribution<std::size_t> pick(0, mesh.triangles.size() - 1);
  std::vector<Vec3> points;
  for (int i = 0; i < count; ++i) {
    if (i % 2 == 0) {
      const auto [a, b, c] = mesh.corners(pick(rng));
      double s = u(rng);
      double t = u(rng);
      if (s + t > 1.0) {
        s = 1.0 - s;
        t = 1.0 - t;
      }
      points.push_back(a + s * (b - a) + t * (c - a) + Vec3(g(rng), g(rng), g(rng)));
    } else {
      points.push_back(
          box.center() +
          box.sizes().cwiseProduct(Vec3(u(rng), u(rng), u(rng)) - Vec3::Constant(0.5)) * 2.0);
    }
  }
  return points;
}

void expect_agrees_with_cgal(const TriangleMesh& mesh, const std::string& label, int count) {
  ASSERT_FALSE(mesh.empty()) << label;
  const MeshBvh bvh(mesh);
  const auto cgal = oracle::make_oracle("cgal", mesh);
  const auto cgal_hint = oracle::make_oracle("cgal-hint", mesh);
  ASSERT_NE(cgal, nullptr);
  ASSERT_NE(cgal_hint, nullptr);
  const double size = mesh.bounds().diagonal().norm();
  int same_triangle = 0;
  QueryHint hint;
  for (const Vec3& p : sample_points(mesh, count, 1234)) {
    const oracle::OracleAnswer want = cgal->closest(p);
    const SurfacePoint got = bvh.closest_point(p);
    const SurfacePoint got_hinted = bvh.closest_point(p, &hint);
    // 1e-9 relative to the distance, or to the mesh size for points on the surface.
    const double tol = 1e-9 * std::max(want.distance, 1e-3 * size);
    ASSERT_TRUE(got.found()) << label;
    EXPECT_NEAR(std::abs(got.signed_distance), want.distance, tol)
        << label << " p=" << p.transpose();
    EXPECT_NEAR(std::abs(got_hinted.signed_distance), want.distance, tol) << label;
    if (got.triangle == want.triangle) {
      EXPECT_LT((got.point - want.point).norm(), tol) << label << " p=" << p.transpose();
      ++same_triangle;
    } else {
      // A tie: another triangle at the same distance (a shared edge or vertex, or symmetry).
      EXPECT_NEAR((p - got.point).norm(), want.distance, tol) << label;
    }
    EXPECT_NEAR(cgal_hint->closest(p).distance, want.distance, tol) << label;
  }
  EXPECT_GT(same_triangle, count / 2) << label;
}

#ifdef HAPSIM_HAVE_CGAL

TEST(MeshBvhOracle, BoxAgreesWithCgal) {
  expect_agrees_with_cgal(make_box(Vec3(0.01, 0.02, 0.03)), "box", 2000);
}

TEST(MeshBvhOracle, BumpySpheresAgreeWithCgal) {
  expect_agrees_with_cgal(make_bumpy_sphere(13500), "bumpy 13.5k", 4000);
  expect_agrees_with_cgal(make_bumpy_sphere(100000), "bumpy 100k", 4000);
}

TEST(MeshBvhOracle, SheetsAgreeWithCgal) {
  expect_agrees_with_cgal(make_sheet(16, 0.2), "sheet 16", 2000);
  expect_agrees_with_cgal(make_sheet(256, 0.2), "sheet 256", 4000);
}

TEST(MeshBvhOracle, KneeStlsAgreeWithCgal) {
  const auto data = test::data_dir();
  HAPSIM_SKIP_WITHOUT_DATA(data && std::filesystem::is_directory(*data / "knee_vhf_left" / "stl"),
                           "knee STLs not found");
  int files = 0;
  for (const auto& entry : std::filesystem::directory_iterator(*data / "knee_vhf_left" / "stl")) {
    if (entry.path().extension() != ".stl") {
      continue;
    }
    const TriangleMesh mesh = load_stl(entry.path());
    expect_agrees_with_cgal(mesh, entry.path().filename().string(), 500);
    ++files;
  }
  EXPECT_GT(files, 0);
}

TEST(MeshBvhOracle, HintedCgalAgreesOnATrajectory) {
  const TriangleMesh mesh = make_bumpy_sphere(13500);
  const MeshBvh bvh(mesh);
  const auto cgal_hint = oracle::make_oracle("cgal-hint", mesh);
  EXPECT_EQ(cgal_hint->name(), "cgal-hint");
  EXPECT_GT(cgal_hint->memory_bytes(), 0u);
  EXPECT_GE(cgal_hint->build_ms(), 0.0);
  QueryHint hint;
  for (int i = 0; i < 3000; ++i) {
    const double t = i * 1e-3;
    const Vec3 dir(std::cos(t), std::sin(t), 0.3 * std::sin(2 * t));
    const Vec3 p = dir.normalized() * (0.05 + 0.005 * std::sin(5 * t));
    const double want = cgal_hint->closest(p).distance;
    EXPECT_NEAR(std::abs(bvh.closest_point(p, &hint).signed_distance), want, 1e-9 * 0.05);
  }
}

#else

TEST(MeshBvhOracle, CgalNotBuilt) {
  GTEST_SKIP() << "CGAL not found at configure time";
}

#endif

}  // namespace
}  // namespace hapsim
