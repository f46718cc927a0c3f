// Simplification to a vertex budget (geometry/mesh_simplify.h) and the Hausdorff distance it
// caused (collision/hausdorff.h): the result is closed, valid, within budget, and every point of
// each surface — sampled at random, independently of the measure's grid — lies within the
// reported bound of the other surface, checked by brute force over every triangle (not the BVH).
#include "hapsim/geometry/mesh_simplify.h"
#include "hapsim/collision/hausdorff.h"
#include "hapsim/collision/point_triangle.h"
#include "hapsim/core/data_dir.h"
#include "hapsim/core/error.h"
#include "hapsim/geometry/mesh_io.h"
#include "hapsim/geometry/mesh_validation.h"
#include "hapsim/geometry/procedural.h"

#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <random>

namespace hapsim {
namespace {

double brute_force_distance(const TriangleMesh& mesh, const Vec3& p) {
  double best = kInf;
  for (std::size_t t = 0; t < mesh.triangle_count(); ++t) {
    const auto c = mesh.corners(t);
    best = std::min(best, closest_point_on_triangle(p, c[0], c[1], c[2]).distance_sq);
  }
  return std::sqrt(best);
}

// Uniform random points on the surface (triangle picked by area, then uniform barycentrics).
std::vector<Vec3> random_surface_points(const TriangleMesh& mesh, int count, unsigned seed) {
  std::vector<double> area;
  for (std::size_t t = 0; t < mesh.triangle_count(); ++t) {
    area.push_back(mesh.face_normal_area2(t).norm());
  }
  std::mt19937 rng(seed);
  std::discrete_distribution<std::size_t> pick(area.begin(), area.end());
  std::uniform_real_distribution<double> u01(0.0, 1.0);
  std::vector<Vec3> points;
  for (int i = 0; i < count; ++i) {
    const auto c = mesh.corners(pick(rng));
    double u = u01(rng);
    double v = u01(rng);
    if (u + v > 1.0) {
      u = 1.0 - u;
      v = 1.0 - v;
    }
    points.push_back(c[0] + u * (c[1] - c[0]) + v * (c[2] - c[0]));
  }
  return points;
}

void expect_simplified_within_reported(const TriangleMesh& source, std::size_t target) {
  const MeshSimplifyResult r = simplify_mesh(source, {.target_vertices = target});
  ASSERT_TRUE(r.valid) << r.problem;
  EXPECT_LE(r.mesh.vertex_count(), target);
  EXPECT_GT(r.mesh.vertex_count(), target / 2) << "the budget should be nearly used";
  const MeshReport report = validate_mesh(r.mesh);
  EXPECT_TRUE(report.closed) << report.summary();
  EXPECT_FALSE(report.has_defects()) << report.summary();
  EXPECT_GT(report.signed_volume, 0.0);
  EXPECT_EQ(report.euler_characteristic, validate_mesh(source).euler_characteristic);

  const HausdorffDistance h = hausdorff_distance(r.mesh, source);
  EXPECT_GT(h.sampled_m(), 0.0) << "simplification changed the surface";
  EXPECT_LE(h.sampled_m(), h.bound_m());
  // Independent: random points of each surface against the other, by brute force.
  double worst_simplified = 0.0;
  for (const Vec3& p : random_surface_points(r.mesh, 400, 7)) {
    const double d = brute_force_distance(source, p);
    worst_simplified = std::max(worst_simplified, d);
    EXPECT_LE(d, h.a_to_b.bound_m + 1e-12);
  }
  double worst_source = 0.0;
  for (const Vec3& p : random_surface_points(source, 400, 11)) {
    const double d = brute_force_distance(r.mesh, p);
    worst_source = std::max(worst_source, d);
    EXPECT_LE(d, h.b_to_a.bound_m + 1e-12);
  }
  // The measure's own samples are exact distances too: brute force agrees at its worst point.
  EXPECT_NEAR(brute_force_distance(source, h.a_to_b.worst_point), h.a_to_b.sampled_m, 1e-12);
  // The bound is not vacuous: random sampling finds a good share of it.
  EXPECT_GT(std::max(worst_simplified, worst_source), 0.3 * h.bound_m());
}

TEST(MeshSimplify, BumpySphereClosedValidWithinReportedHausdorff) {
  const TriangleMesh sphere = make_bumpy_sphere(13500);
  expect_simplified_within_reported(sphere, 800);
}

TEST(MeshSimplify, RealKneePatellaClosedValidWithinReportedHausdorff) {
  const auto data = find_data_dir(HAPSIM_TEST_DATA_DIR);
  const std::filesystem::path file =
      data ? *data / "knee_vhf_left/stl/VHF_Left_Bone_Patella_smooth.stl" : "";
  if (!data || !std::filesystem::exists(file)) {
    GTEST_SKIP() << "real data folder not found (set HAPSIM_DATA or place ../shared/data)";
  }
  MeshLoadOptions options;
  options.scale = 0.001;
  expect_simplified_within_reported(load_mesh(file, options), 300);
}

TEST(MeshSimplify, WithinBudgetUnchangedAndBadBudgetRefused) {
  const TriangleMesh box = make_box(Vec3(0.01, 0.02, 0.03));
  const MeshSimplifyResult r = simplify_mesh(box, {.target_vertices = 100});
  EXPECT_TRUE(r.valid);
  EXPECT_EQ(r.mesh.vertices, box.vertices);
  EXPECT_THROW((void)simplify_mesh(box, {.target_vertices = 0}), Error);
  EXPECT_THROW((void)simplify_mesh(TriangleMesh{}, {.target_vertices = 10}), Error);
}

TEST(Hausdorff, OffsetSphereDistanceIsTheOffset) {
  // Two concentric fine spheres 2 mm apart: both one-sided distances are about 2 mm, and the
  // bound holds the true value (2 mm less the chord sag of the facets).
  const TriangleMesh inner = make_uv_sphere(0.05, 96, 48);
  const TriangleMesh outer = make_uv_sphere(0.052, 96, 48);
  const HausdorffDistance h = hausdorff_distance(inner, outer);
  EXPECT_NEAR(h.a_to_b.sampled_m, 0.002, 2e-4);
  EXPECT_NEAR(h.b_to_a.sampled_m, 0.002, 2e-4);
  EXPECT_GE(h.bound_m(), 0.002);
  EXPECT_THROW((void)one_sided_hausdorff(inner, outer, 0.0), Error);
}

}  // namespace
}  // namespace hapsim
