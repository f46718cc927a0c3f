// Validation on hand-made bad meshes: each defect is detected, counted, and (where a repair
// exists) repaired; nothing crashes on garbage.
#include "hapsim/geometry/mesh_validation.h"
#include "hapsim/geometry/procedural.h"
#include "hapsim/geometry/vertex_welding.h"

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <limits>
#include <random>

namespace hapsim {
namespace {

TriangleMesh unit_box() {
  return make_box(Vec3(0.5, 0.5, 0.5));
}

TEST(MeshValidation, CleanBoxHasNoDefects) {
  const MeshReport r = validate_mesh(unit_box());
  EXPECT_EQ(r.vertex_count, 8u);
  EXPECT_EQ(r.triangle_count, 12u);
  EXPECT_EQ(r.edge_count, 18u);
  EXPECT_TRUE(r.closed);
  EXPECT_FALSE(r.has_defects());
  EXPECT_EQ(r.components, 1u);
  EXPECT_EQ(r.euler_characteristic, 2);
  EXPECT_NEAR(r.signed_volume, 1.0, 1e-12);
  EXPECT_NEAR(r.surface_area, 6.0, 1e-12);
  EXPECT_NE(r.summary().find("no defects"), std::string::npos);
}

TEST(MeshValidation, NanAndInfVerticesAreCountedWithoutCrashing) {
  for (double bad : {std::numeric_limits<double>::quiet_NaN(), kInf, -kInf}) {
    TriangleMesh m = unit_box();
    m.vertices[3].y() = bad;
    const MeshReport r = validate_mesh(m);
    EXPECT_EQ(r.non_finite_vertices, 1u);
    EXPECT_EQ(r.count(MeshDefect::kNonFiniteVertex), 1u);
    EXPECT_EQ(r.inverted_components, 0u);  // volume unknown: not judged
    EXPECT_TRUE(r.bounds.isApprox(Box3(Vec3(-0.5, -0.5, -0.5), Vec3(0.5, 0.5, 0.5))));
    // JSON stays valid (no NaN literal).
    const auto j = nlohmann::json::parse(r.to_json());
    EXPECT_EQ(j["non_finite_vertices"], 1);
    EXPECT_NE(r.summary().find("non_finite_vertices=1"), std::string::npos);

    // Repair drops the triangles that use it and the vertex itself; what is left is open.
    ValidationPolicy p;
    p[MeshDefect::kNonFiniteVertex] = DefectAction::kRepair;
    const MeshRepairStats s = repair_mesh(m, p);
    EXPECT_GT(s.dropped_non_finite, 0u);
    const MeshReport after = validate_mesh(m);
    EXPECT_EQ(after.non_finite_vertices, 0u);
    EXPECT_EQ(after.vertex_count, 7u);
    EXPECT_GT(after.open_edges, 0u);
  }
}

TEST(MeshValidation, DegenerateTriangles) {
  TriangleMesh m = unit_box();
  m.triangles.push_back({0, 0, 1});  // repeated index
  const auto base = static_cast<std::uint32_t>(m.vertices.size());
  m.vertices.push_back(Vec3(0, 0, 0));  // collinear, distinct indices
  m.vertices.push_back(Vec3(0.1, 0.1, 0.1));
  m.vertices.push_back(Vec3(0.3, 0.3, 0.3));
  m.triangles.push_back({base, base + 1, base + 2});
  const MeshReport r = validate_mesh(m);
  EXPECT_EQ(r.degenerate_triangles, 2u);
  // A thin but real triangle is not degenerate.
  TriangleMesh thin;
  thin.vertices = {Vec3(0, 0, 0), Vec3(1, 0, 0), Vec3(0.5, 1e-4, 0)};
  thin.triangles = {{0, 1, 2}};
  EXPECT_EQ(validate_mesh(thin).degenerate_triangles, 0u);

  const MeshRepairStats s = repair_mesh(m, ValidationPolicy{});
  EXPECT_EQ(s.dropped_degenerate, 2u);
  EXPECT_EQ(s.removed_vertices, 3u);
  const MeshReport after = validate_mesh(m);
  EXPECT_FALSE(after.has_defects()) << after.summary();
  EXPECT_TRUE(after.closed);
}

TEST(MeshValidation, DuplicateTrianglesInAnyOrder) {
  TriangleMesh m = unit_box();
  m.triangles.push_back(m.triangles[0]);
  const TriangleIndices t = m.triangles[5];
  m.triangles.push_back({t[2], t[1], t[0]});  // reversed copy
  const MeshReport r = validate_mesh(m);
  EXPECT_EQ(r.duplicate_triangles, 2u);
  EXPECT_FALSE(r.closed);
  EXPECT_EQ(r.non_manifold_edges, 0u);  // reported once, as duplicates
  repair_mesh(m, ValidationPolicy{});
  EXPECT_EQ(m.triangle_count(), 12u);
  EXPECT_TRUE(validate_mesh(m).closed);
}

TEST(MeshValidation, OpenEdges) {
  TriangleMesh m = unit_box();
  m.triangles.pop_back();
  const MeshReport r = validate_mesh(m);
  EXPECT_EQ(r.open_edges, 3u);
  EXPECT_FALSE(r.closed);
  EXPECT_EQ(r.inverted_components, 0u);
  EXPECT_EQ(r.euler_characteristic, 1);
}

TEST(MeshValidation, NonManifoldEdgeWithThreeFaces) {
  TriangleMesh m = unit_box();
  // A fin on the edge of triangle 0: that edge now has three faces.
  const TriangleIndices t = m.triangles[0];
  m.vertices.push_back(Vec3(2, 2, 2));
  m.triangles.push_back({t[0], t[1], static_cast<std::uint32_t>(m.vertices.size() - 1)});
  const MeshReport r = validate_mesh(m);
  EXPECT_EQ(r.non_manifold_edges, 1u);
  EXPECT_EQ(r.open_edges, 2u);
  EXPECT_FALSE(r.closed);
  EXPECT_EQ(r.components, 1u);
  // No automatic repair exists: repair leaves it, and says nothing changed.
  const MeshRepairStats s = repair_mesh(m, ValidationPolicy::repair_all());
  EXPECT_EQ(validate_mesh(m).non_manifold_edges, 1u);
  EXPECT_FALSE(s.any());
}

TEST(MeshValidation, FlippedFaceIsInconsistentAndRepaired) {
  TriangleMesh m = unit_box();
  std::swap(m.triangles[4][1], m.triangles[4][2]);
  const MeshReport r = validate_mesh(m);
  EXPECT_EQ(r.inconsistent_edges, 3u);
  EXPECT_FALSE(r.closed);
  EXPECT_EQ(r.open_edges, 0u);
  EXPECT_EQ(r.inverted_components, 0u);

  ValidationPolicy p;
  p[MeshDefect::kInconsistentOrientation] = DefectAction::kRepair;
  const MeshRepairStats s = repair_mesh(m, p);
  EXPECT_EQ(s.reoriented_triangles, 1u);  // the minority flips, not the other eleven
  const MeshReport after = validate_mesh(m);
  EXPECT_TRUE(after.closed);
  EXPECT_FALSE(after.has_defects());
  EXPECT_NEAR(after.signed_volume, 1.0, 1e-12);
}

TEST(MeshValidation, MostlyFlippedBoxEndsOutward) {
  // Eleven of twelve faces inward: orientation repair keeps the majority (inward), then the
  // inside-out repair turns the whole component outward.
  TriangleMesh m = unit_box();
  flip_orientation(m);
  std::swap(m.triangles[0][1], m.triangles[0][2]);
  repair_mesh(m, ValidationPolicy::repair_all());
  const MeshReport after = validate_mesh(m);
  EXPECT_TRUE(after.closed);
  EXPECT_NEAR(after.signed_volume, 1.0, 1e-12);
}

TEST(MeshValidation, InsideOutClosedMesh) {
  TriangleMesh m = make_uv_sphere(0.1, 24, 12);
  flip_orientation(m);
  const MeshReport r = validate_mesh(m);
  EXPECT_TRUE(r.closed);
  EXPECT_EQ(r.inverted_components, 1u);
  EXPECT_LT(r.signed_volume, 0.0);
  const MeshRepairStats s = repair_mesh(m, ValidationPolicy{});  // default: flip
  EXPECT_EQ(s.flipped_components, 1u);
  EXPECT_GT(validate_mesh(m).signed_volume, 0.0);
  EXPECT_FALSE(validate_mesh(m).has_defects());
  for (std::size_t v = 0; v < m.vertex_count(); ++v) {
    EXPECT_GT(m.vertex_normals[v].dot(m.vertices[v]), 0.0);
  }
}

TEST(MeshValidation, HollowShellCavityIsNotInverted) {
  TriangleMesh outer = make_uv_sphere(0.1, 24, 12);
  TriangleMesh inner = make_uv_sphere(0.05, 24, 12);
  flip_orientation(inner);  // the cavity wall faces into the cavity
  outer.append(inner);
  const MeshReport r = validate_mesh(outer);
  EXPECT_TRUE(r.closed);
  EXPECT_EQ(r.components, 2u);
  EXPECT_EQ(r.inverted_components, 0u);
  EXPECT_GT(r.signed_volume, 0.0);
}

TEST(MeshValidation, OneOfTwoComponentsInsideOut) {
  TriangleMesh a = unit_box();
  TriangleMesh b = unit_box();
  flip_orientation(b);
  b.transform(Iso3(Eigen::Translation3d(3, 0, 0)));
  a.append(b);
  EXPECT_EQ(validate_mesh(a).inverted_components, 1u);
  repair_mesh(a, ValidationPolicy{});
  EXPECT_NEAR(validate_mesh(a).signed_volume, 2.0, 1e-12);
}

TEST(MeshValidation, OutOfRangeIndex) {
  TriangleMesh m = unit_box();
  m.triangles.push_back({0, 1, 99});
  m.triangles.push_back({kNoTriangle, 1, 2});
  const MeshReport r = validate_mesh(m);
  EXPECT_EQ(r.out_of_range_triangles, 2u);
  EXPECT_FALSE(r.closed);
  // Repairs that renumber are held back while bad indices remain.
  ValidationPolicy keep_bad = ValidationPolicy::warn_only();
  keep_bad[MeshDefect::kUnusedVertex] = DefectAction::kRepair;
  m.vertices.push_back(Vec3(5, 5, 5));
  repair_mesh(m, keep_bad);
  EXPECT_EQ(m.vertex_count(), 9u);
  // Dropping them restores the box.
  ValidationPolicy p;
  p[MeshDefect::kOutOfRangeIndex] = DefectAction::kRepair;
  const MeshRepairStats s = repair_mesh(m, p);
  EXPECT_EQ(s.dropped_out_of_range, 2u);
  EXPECT_EQ(s.removed_vertices, 1u);
  EXPECT_FALSE(validate_mesh(m).has_defects());
}

TEST(MeshValidation, EmptyAndTinyMeshes) {
  TriangleMesh empty;
  MeshReport r = validate_mesh(empty);
  EXPECT_FALSE(r.closed);
  EXPECT_EQ(r.components, 0u);
  EXPECT_TRUE(r.bounds.isEmpty());
  EXPECT_TRUE(nlohmann::json::accept(r.to_json()));
  repair_mesh(empty, ValidationPolicy::repair_all());

  TriangleMesh points;
  points.vertices = {Vec3(1, 1, 1), Vec3(1, 1, 1), Vec3(1, 1, 1)};
  points.triangles = {{0, 1, 2}};
  r = validate_mesh(points);
  EXPECT_EQ(r.degenerate_triangles, 1u);  // zero bounding box: everything is degenerate
}

TEST(MeshValidation, ReportJsonAndNames) {
  TriangleMesh m = unit_box();
  m.triangles.pop_back();
  MeshReport r = validate_mesh(m);
  r.notes.push_back("a note");
  const auto j = nlohmann::json::parse(r.to_json(2));
  EXPECT_EQ(j["open_edges"], 3);
  EXPECT_EQ(j["closed"], false);
  EXPECT_EQ(j["triangles"], 11);
  EXPECT_EQ(j["notes"][0], "a note");
  for (std::size_t d = 0; d < kMeshDefectCount; ++d) {
    EXPECT_TRUE(j.contains(std::string(to_string(static_cast<MeshDefect>(d)))));
  }
  EXPECT_EQ(to_string(DefectAction::kRefuse), "refuse");
}

TEST(MeshValidation, GarbageNeverCrashes) {
  std::mt19937 rng(1234);
  std::uniform_int_distribution<std::uint32_t> index(0, 40);
  std::uniform_real_distribution<double> coord(-1.0, 1.0);
  std::uniform_int_distribution<int> special(0, 20);
  for (int trial = 0; trial < 200; ++trial) {
    TriangleMesh m;
    const int nv = trial % 30;
    for (int v = 0; v < nv; ++v) {
      Vec3 p(coord(rng), coord(rng), coord(rng));
      const int s = special(rng);
      if (s == 0) {
        p.x() = std::numeric_limits<double>::quiet_NaN();
      } else if (s == 1) {
        p.z() = -kInf;
      } else if (s == 2 && v > 0) {
        p = m.vertices[0];
      }
      m.vertices.push_back(p);
    }
    for (int t = 0; t < 40; ++t) {
      m.triangles.push_back({index(rng), index(rng), index(rng)});
    }
    const MeshReport r = validate_mesh(m);
    EXPECT_EQ(r.triangle_count, 40u);
    (void)r.summary();
    EXPECT_TRUE(nlohmann::json::accept(r.to_json()));
    TriangleMesh copy = m;
    repair_mesh(copy, ValidationPolicy::repair_all());
    ValidationPolicy all;
    all.actions.fill(DefectAction::kRepair);
    repair_mesh(m, all);
    const MeshReport after = validate_mesh(m);
    EXPECT_EQ(after.out_of_range_triangles, 0u);
    EXPECT_EQ(after.non_finite_vertices, 0u);
    EXPECT_EQ(after.degenerate_triangles, 0u);
    EXPECT_EQ(after.duplicate_triangles, 0u);
    EXPECT_EQ(after.unused_vertices, 0u);
    (void)weld_vertices(copy, 0.1);
    (void)validate_mesh(copy);
  }
}

TEST(VertexWelding, ExactAndToleranceWeld) {
  // Triangle soup of a box: 36 corners, 8 distinct positions.
  const TriangleMesh box = unit_box();
  TriangleMesh soup;
  for (std::size_t t = 0; t < box.triangle_count(); ++t) {
    const auto c = box.corners(t);
    const auto base = static_cast<std::uint32_t>(soup.vertices.size());
    soup.vertices.insert(soup.vertices.end(), c.begin(), c.end());
    soup.triangles.push_back({base, base + 1, base + 2});
  }
  EXPECT_EQ(validate_mesh(soup).open_edges, 36u);
  TriangleMesh exact = soup;
  EXPECT_EQ(weld_vertices(exact), 28u);
  EXPECT_TRUE(validate_mesh(exact).closed);

  // Jitter below the tolerance: exact welding cannot close it, tolerance welding does.
  TriangleMesh jittered = soup;
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> jitter(-1e-7, 1e-7);
  for (Vec3& v : jittered.vertices) {
    v += Vec3(jitter(rng), jitter(rng), jitter(rng));
  }
  TriangleMesh j2 = jittered;
  weld_vertices(j2);
  EXPECT_FALSE(validate_mesh(j2).closed);
  EXPECT_EQ(weld_vertices(jittered, 1e-6), 28u);
  EXPECT_TRUE(validate_mesh(jittered).closed);

  // −0 and +0 are the same position; non-finite vertices merge only when bit-identical.
  TriangleMesh zeros;
  zeros.vertices = {Vec3(0, 0, 0), Vec3(-0.0, 0, -0.0),
                    Vec3(std::numeric_limits<double>::quiet_NaN(), 0, 0),
                    Vec3(std::numeric_limits<double>::quiet_NaN(), 0, 0)};
  zeros.vertices.push_back(Vec3(std::numeric_limits<double>::quiet_NaN(), 1, 0));
  EXPECT_EQ(weld_vertices(zeros), 2u);  // −0 with +0, and the bit-identical NaN pair
  EXPECT_EQ(zeros.vertex_count(), 3u);
}

}  // namespace
}  // namespace hapsim
