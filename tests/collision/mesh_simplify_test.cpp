// Simplification to a vertex budget (geometry/mesh_simplify.h) and the Hausdorff distance it
// caused (collision/hausdorff.h): the result is closed, valid, within budget, and every point of
// each surface — sampled at random, independently of the measure's grid — lies within the
// reported bound of the other surface, checked by brute force over every triangle (not the BVH).
#include "hapsim/geometry/mesh_simplify.h"
#include "hapsim/collision/hausdorff.h"
#include "hapsim/collision/mesh_bvh.h"
#include "hapsim/collision/point_triangle.h"
#include "hapsim/core/data_dir.h"
#include "hapsim/core/error.h"
#include "hapsim/geometry/csg.h"
#include "hapsim/geometry/mesh_io.h"
#include "hapsim/geometry/mesh_unfold.h"
#include "hapsim/geometry/mesh_validation.h"
#include "hapsim/geometry/polygonizer.h"
#include "hapsim/geometry/procedural.h"
#include "support/test_data.h"

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
  const std::filesystem::path file =
      test::data_path("knee_vhf_left/stl/VHF_Left_Bone_Patella_smooth.stl");
  HAPSIM_SKIP_WITHOUT_DATA(std::filesystem::exists(file),
                           "real knee patella not found at " << file);
  MeshLoadOptions options;
  options.scale = 0.001;
  expect_simplified_within_reported(load_mesh(file, options), 300);
}

// The knee's patellar tendon (a 24 x 5 x 48 mm strap, scripts/knee/patellar_tendon.csg.json)
// polygonised at 0.8 mm and simplified to 200 vertices: meshoptimizer left 39 fins at the
// strap's edges, beside which the closest point's pseudo-normal called 4% of the points near
// the strap inside when they were outside (a fingertip dragged across it lost the tendon). The
// result must have no fold, and inside/outside must agree with the strap's own exact signed
// distance at every point farther from its surface than the simplification's Hausdorff bound.
TEST(MeshSimplify, SharpEdgedStrapHasNoFoldAndTheRightInsideEverywhere) {
  const CsgSolid strap = CsgSolid::block(Vec3(0.012, 0.0025, 0.024));
  PolygonizeOptions popt;
  popt.cell_size_m = 0.0008;
  popt.threads = 1;
  TriangleMesh source = polygonize(strap, popt);
  collapse_degenerate_triangles(source);  // as `hapsim polygonize` does before writing
  ASSERT_EQ(validate_mesh(source).folded_edges, 0U);
  const MeshSimplifyResult r = simplify_mesh(source, {.target_vertices = 200});
  ASSERT_TRUE(r.valid) << r.problem << " after " << r.attempts << " attempts";
  EXPECT_EQ(validate_mesh(r.mesh).folded_edges, 0U);
  const HausdorffDistance h = hausdorff_distance(r.mesh, source);
  const MeshBvh bvh(r.mesh);
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> x(-0.016, 0.016), y(-0.0065, 0.0065), z(-0.028, 0.028);
  int compared = 0;
  int wrong = 0;
  for (int i = 0; i < 20000; ++i) {
    const Vec3 p(x(rng), y(rng), z(rng));
    const double exact = strap.distance(p);
    if (std::abs(exact) <= h.bound_m()) {
      continue;  // within the simplification's error the side is not defined
    }
    ++compared;
    wrong += (bvh.closest_point(p).signed_distance < 0.0) != (exact < 0.0) ? 1 : 0;
  }
  EXPECT_GT(compared, 15000);
  EXPECT_EQ(wrong, 0) << "of " << compared << " points";
}

// A flat tetrahedron's base edges are folds (its sides turn back over the base, normals 170
// degrees apart), a regular one's are not (109.5 degrees); unfold_edges leaves such a closed
// solid alone (no flip or collapse keeps it a closed tetrahedron).
TEST(MeshValidation, FlatTetrahedronBaseEdgesAreFolds) {
  const auto tetra = [](double apex_height_m) {
    TriangleMesh m;
    const double s = 0.01;
    m.vertices = {Vec3(0, 0, 0), Vec3(s, 0, 0), Vec3(0.5 * s, 0.866 * s, 0),
                  Vec3(0.5 * s, 0.2887 * s, apex_height_m)};
    m.triangles = {{0, 2, 1}, {0, 1, 3}, {1, 2, 3}, {2, 0, 3}};
    return m;
  };
  EXPECT_EQ(validate_mesh(tetra(0.00816)).folded_edges, 0U);  // regular
  // Apex 0.25 mm over a 10 mm base: each side leans 170 degrees from the base's normal.
  TriangleMesh flat = tetra(0.00025);
  EXPECT_EQ(validate_mesh(flat).folded_edges, 3U);
  EXPECT_NE(validate_mesh(flat).summary().find("3 folded edges"), std::string::npos);
  EXPECT_EQ(unfold_edges(flat), 0U);
  EXPECT_TRUE(validate_mesh(flat).closed);
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
