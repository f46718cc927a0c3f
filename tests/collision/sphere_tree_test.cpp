#include "hapsim/collision/sphere_tree.h"

#include "hapsim/collision/mesh_bvh.h"
#include "hapsim/collision/point_triangle.h"
#include "hapsim/geometry/procedural.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>
#include <set>
#include <utility>
#include <vector>

namespace hapsim {
namespace {

constexpr double kContainTol = 1e-12;  // relative slack for "inside the sphere"

// Exact answer by testing every triangle, resolved with the tree's own sign data.
SurfacePoint brute_force(const SphereTree& tree, const Vec3& p) {
  const TriangleMesh& mesh = tree.mesh();
  double best = kInf;
  std::uint32_t best_t = kNoTriangle;
  TriangleClosest best_c{};
  for (std::uint32_t t = 0; t < mesh.triangle_count(); ++t) {
    const auto c = mesh.corners(t);
    const TriangleClosest tc = closest_point_on_triangle(p, c[0], c[1], c[2]);
    if (tc.distance_sq < best) {
      best = tc.distance_sq;
      best_t = t;
      best_c = tc;
    }
  }
  return tree.signed_surface().resolve(mesh, p, best_t, best_c);
}

void expect_same_answer(const SurfacePoint& got, const SurfacePoint& want, const Vec3& p) {
  ASSERT_TRUE(got.found());
  const double scale = std::max(std::abs(want.signed_distance), 1e-300);
  EXPECT_NEAR(std::abs(got.signed_distance), std::abs(want.signed_distance), 1e-12 * scale)
      << "p = " << p.transpose();
  EXPECT_EQ(got.inside(), want.inside())
      << "p = " << p.transpose() << " d = " << want.signed_distance;
  EXPECT_NEAR((got.point - p).norm(), std::abs(got.signed_distance), 1e-12 * (scale + 1e-9));
}

void check_invariants(const SphereTree& tree, int max_leaf) {
  const TriangleMesh& mesh = tree.mesh();
  const std::size_t n = tree.node_count();
  ASSERT_GT(n, 0U);
  EXPECT_EQ(tree.stats().nodes, n);
  EXPECT_EQ(tree.stats().leaves, tree.leaf_count());
  EXPECT_EQ(tree.node_level(0), 0U);
  std::vector<int> parents(n, 0);
  std::size_t max_level = 0;
  std::size_t leaves_seen = 0;
  for (std::size_t i = 0; i < n; ++i) {
    const Sphere parent = tree.node_sphere(i);
    max_level = std::max(max_level, tree.node_level(i));
    const auto children = tree.node_children(i);
    if (children.empty()) {
      ++leaves_seen;
    }
    for (std::uint32_t c : children) {
      ASSERT_LT(c, n);
      ++parents[c];
      EXPECT_EQ(tree.node_level(c), tree.node_level(i) + 1);
      const Sphere child = tree.node_sphere(c);
      // Seed 000 §3.1: the parent bounds the child sphere itself, not only its triangles.
      EXPECT_LE((child.center - parent.center).norm() + child.radius,
                parent.radius * (1.0 + kContainTol))
          << "node " << i << " child " << c;
    }
  }
  EXPECT_EQ(parents[0], 0);
  for (std::size_t i = 1; i < n; ++i) {
    EXPECT_EQ(parents[i], 1) << "node " << i;
  }
  EXPECT_EQ(tree.stats().depth, max_level + 1);
  EXPECT_EQ(leaves_seen, tree.leaf_count());

  std::vector<int> seen(mesh.triangle_count(), 0);
  for (std::size_t leaf = 0; leaf < tree.leaf_count(); ++leaf) {
    const std::size_t node = tree.leaf_node(leaf);
    EXPECT_TRUE(tree.node_children(node).empty());
    const auto tris = tree.leaf_triangles(leaf);
    EXPECT_GE(tris.size(), 1U);
    EXPECT_LE(tris.size(), static_cast<std::size_t>(max_leaf));
    const Sphere s = tree.node_sphere(node);
    for (std::uint32_t t : tris) {
      ASSERT_LT(t, mesh.triangle_count());
      ++seen[t];
      for (const Vec3& v : mesh.corners(t)) {
        EXPECT_LE((v - s.center).norm(), s.radius * (1.0 + kContainTol))
            << "leaf " << leaf << " triangle " << t;
      }
    }
  }
  for (std::size_t t = 0; t < seen.size(); ++t) {
    EXPECT_EQ(seen[t], 1) << "triangle " << t;
  }
}

// Query points: near the surface (either side, within `near_m`) and anywhere in a box twice the
// mesh's size.
std::vector<Vec3> sample_points(const TriangleMesh& mesh, std::size_t count, double near_m,
                                unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_int_distribution<std::size_t> pick(0, mesh.triangle_count() - 1);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  const Box3 box = mesh.bounds();
  const Vec3 centre = box.center();
  const Vec3 half = box.sizes().cwiseMax(1e-3);
  std::vector<Vec3> pts;
  for (std::size_t i = 0; i < count; ++i) {
    if (i % 2 == 0) {
      const auto c = mesh.corners(pick(rng));
      double a = unit(rng);
      double b = unit(rng);
      if (a + b > 1.0) {
        a = 1.0 - a;
        b = 1.0 - b;
      }
      const Vec3 on = c[0] + a * (c[1] - c[0]) + b * (c[2] - c[0]);
      const Vec3 n = (c[1] - c[0]).cross(c[2] - c[0]).normalized();
      pts.push_back(on + (2.0 * unit(rng) - 1.0) * near_m * n);
    } else {
      pts.push_back(centre +
                    Vec3(2.0 * unit(rng) - 1.0, 2.0 * unit(rng) - 1.0, 2.0 * unit(rng) - 1.0)
                        .cwiseProduct(half));
    }
  }
  return pts;
}

struct MeshCase {
  const char* name;
  TriangleMesh mesh;
};

std::vector<MeshCase> test_meshes() {
  std::vector<MeshCase> cases;
  cases.push_back({"box", make_box(Vec3(0.03, 0.02, 0.01))});
  cases.push_back({"bumpy13k", make_bumpy_sphere(13500)});
  cases.push_back({"sheet", make_sheet(41, 0.2)});
  cases.push_back({"uv_sphere", make_uv_sphere(0.04, 24, 12)});
  return cases;
}

TEST(SphereTree, InvariantsOnSeveralMeshesAndOptions) {
  for (const MeshCase& mc : test_meshes()) {
    for (const auto& [branching, leaf] :
         std::vector<std::pair<int, int>>{{4, 4}, {2, 1}, {8, 3}, {3, 7}}) {
      SCOPED_TRACE(std::string(mc.name) + " b=" + std::to_string(branching) +
                   " leaf=" + std::to_string(leaf));
      const SphereTree tree(mc.mesh, {branching, leaf, {}});
      check_invariants(tree, leaf);
      for (std::size_t i = 0; i < tree.node_count(); ++i) {
        EXPECT_LE(tree.node_children(i).size(), static_cast<std::size_t>(branching));
      }
    }
  }
}

TEST(SphereTree, StatsAreFilled) {
  const TriangleMesh mesh = make_bumpy_sphere(13500);
  const SphereTree tree(mesh);
  const SphereTreeStats& s = tree.stats();
  EXPECT_EQ(s.nodes, tree.node_count());
  EXPECT_GE(s.leaves * 4, mesh.triangle_count());
  EXPECT_GE(s.depth, 6U);   // log4(13.5k / 4) ≈ 5.9
  EXPECT_LE(s.depth, 12U);  // median splits keep it balanced
  EXPECT_GT(s.memory_bytes, tree.signed_surface().memory_bytes());
  EXPECT_EQ(s.memory_bytes, tree.memory_bytes());
  // Leaves are minimal spheres of their corners; parents bound children so are looser.
  EXPECT_NEAR(s.leaf_tightness, 1.0, 1e-9);
  EXPECT_GE(s.inner_tightness, 1.0 - 1e-12);
  EXPECT_LT(s.inner_tightness, 1.6);
}

TEST(SphereTree, ReportsProgress) {
  const TriangleMesh mesh = make_bumpy_sphere(20000);
  std::vector<double> fractions;
  SphereTreeOptions options;
  options.progress = [&](std::string_view, double f) { fractions.push_back(f); };
  const SphereTree tree(mesh, options);
  ASSERT_GE(fractions.size(), 3U);
  EXPECT_TRUE(std::is_sorted(fractions.begin(), fractions.end()));
  EXPECT_GE(fractions.front(), 0.0);
  EXPECT_EQ(fractions.back(), 1.0);
}

TEST(SphereTree, EmptyMeshFindsNothing) {
  const TriangleMesh mesh;
  const SphereTree tree(mesh);
  EXPECT_EQ(tree.node_count(), 0U);
  EXPECT_FALSE(tree.closest_point(Vec3::Zero()).found());
  SurfacePoint out;
  EXPECT_FALSE(tree.contact_within(Vec3::Zero(), 1.0, &out));
}

TEST(SphereTree, ClosestPointMatchesBruteForce) {
  for (const MeshCase& mc : test_meshes()) {
    SCOPED_TRACE(mc.name);
    for (int branching : {4, 2, 6}) {
      const SphereTree tree(mc.mesh, {branching, 4, {}});
      for (const Vec3& p : sample_points(mc.mesh, 400, 0.004, 17)) {
        expect_same_answer(tree.closest_point(p), brute_force(tree, p), p);
      }
    }
  }
}

TEST(SphereTree, AgreesWithExactBvh) {
  // Same kernel and sign data as MeshBvh: same distance, same side, same normal.
  for (const MeshCase& mc : test_meshes()) {
    SCOPED_TRACE(mc.name);
    const SphereTree tree(mc.mesh);
    const MeshBvh bvh(mc.mesh);
    QueryHint hint_tree;
    QueryHint hint_bvh;
    for (const Vec3& p : sample_points(mc.mesh, 1000, 0.004, 51)) {
      const SurfacePoint a = tree.closest_point(p, &hint_tree);
      const SurfacePoint b = bvh.closest_point(p, &hint_bvh);
      expect_same_answer(a, b, p);
      if (std::abs(b.signed_distance) > 1e-9) {
        EXPECT_NEAR((a.normal - b.normal).norm(), 0.0, 1e-9);
      }
    }
  }
}

TEST(SphereTree, QueryOnTheSurfaceAndAtVertices) {
  const TriangleMesh mesh = make_bumpy_sphere(2000);
  const SphereTree tree(mesh);
  for (std::size_t v = 0; v < mesh.vertex_count(); v += 7) {
    const SurfacePoint sp = tree.closest_point(mesh.vertices[v]);
    ASSERT_TRUE(sp.found());
    EXPECT_LE(std::abs(sp.signed_distance), 1e-15);
  }
}

// A haptic probe trajectory: small steps (0.2 mm) along a wandering path near the surface.
std::vector<Vec3> trajectory(const TriangleMesh& mesh, std::size_t steps, unsigned seed) {
  std::mt19937 rng(seed);
  std::normal_distribution<double> g(0.0, 1.0);
  const double radius = 0.5 * mesh.bounds().sizes().maxCoeff();
  std::vector<Vec3> pts;
  Vec3 dir = Vec3(1, 0.3, 0.2).normalized();
  double r = radius * 1.02;
  for (std::size_t i = 0; i < steps; ++i) {
    Vec3 turn(g(rng), g(rng), g(rng));
    dir = (dir + 0.02 * turn).normalized();
    r = std::clamp(r + 2e-4 * g(rng), 0.85 * radius, 1.15 * radius);
    pts.push_back(mesh.bounds().center() + r * dir);
  }
  return pts;
}

TEST(SphereTree, HintChangesTheWorkNeverTheAnswer) {
  const TriangleMesh mesh = make_bumpy_sphere(13500);
  const SphereTree tree(mesh);
  SphereQueryCounters cold;
  SphereQueryCounters warm;
  QueryHint hint;
  for (const Vec3& p : trajectory(mesh, 2000, 5)) {
    const SurfacePoint a = tree.closest_point_counted(p, nullptr, &cold);
    const SurfacePoint b = tree.closest_point_counted(p, &hint, &warm);
    expect_same_answer(b, a, p);
    EXPECT_EQ(hint.triangle, b.triangle);
    // The uncounted fast path returns the same.
    QueryHint h2{hint.triangle};
    expect_same_answer(tree.closest_point(p, &h2), a, p);
  }
  EXPECT_LT(warm.nodes_visited, cold.nodes_visited);
  EXPECT_LT(warm.triangles_tested, cold.triangles_tested);

  // A wrong hint (far side of the body) or a garbage one still gives the exact answer.
  for (const Vec3& p : sample_points(mesh, 200, 0.003, 9)) {
    QueryHint far{static_cast<std::uint32_t>(
        tree.closest_point(Vec3(-p.x(), -p.y(), -p.z()) * 1.3).triangle)};
    expect_same_answer(tree.closest_point(p, &far), brute_force(tree, p), p);
    QueryHint junk{static_cast<std::uint32_t>(mesh.triangle_count() + 5)};
    expect_same_answer(tree.closest_point(p, &junk), brute_force(tree, p), p);
  }
}

TEST(SphereTree, ContactWithinIffDistanceAtMostRadius) {
  for (const MeshCase& mc : test_meshes()) {
    SCOPED_TRACE(mc.name);
    const SphereTree tree(mc.mesh);
    int hits = 0;
    int misses = 0;
    for (const Vec3& p : sample_points(mc.mesh, 300, 0.004, 23)) {
      const SurfacePoint exact = brute_force(tree, p);
      const double d = std::abs(exact.signed_distance);
      for (double factor : {0.5, 0.999, 1.001, 2.0}) {
        const double r = d * factor;
        SurfacePoint out;
        QueryHint hint;
        const bool within = tree.contact_within(p, r, &out, &hint);
        EXPECT_EQ(within, d <= r) << "d = " << d << " r = " << r;
        if (within) {
          ++hits;
          expect_same_answer(out, exact, p);
          EXPECT_EQ(hint.triangle, out.triangle);
        } else {
          ++misses;
          EXPECT_EQ(hint.triangle, kNoTriangle);
        }
      }
    }
    EXPECT_GT(hits, 100);
    EXPECT_GT(misses, 100);
  }
  const TriangleMesh mesh = make_box(Vec3(0.01, 0.01, 0.01));
  const SphereTree tree(mesh);
  SurfacePoint out;
  EXPECT_FALSE(tree.contact_within(Vec3::Zero(), -1.0, &out));
  EXPECT_TRUE(tree.contact_within(Vec3(0.01, 0.0, 0.0), 0.0, &out));  // on the face
  EXPECT_NEAR(out.signed_distance, 0.0, 1e-18);
}

TEST(SphereTree, ContactWithinExitsEarly) {
  const TriangleMesh mesh = make_bumpy_sphere(13500);
  const SphereTree tree(mesh);
  // Far from the body with a small radius: the root sphere alone rules it out.
  SphereQueryCounters far;
  EXPECT_FALSE(tree.contact_within_counted(Vec3(0.5, 0, 0), 0.01, nullptr, nullptr, &far));
  EXPECT_EQ(far.nodes_visited, 0U);
  EXPECT_EQ(far.triangles_tested, 0U);
  // 1 cm outside with a 1 mm radius: a few spheres, far fewer than a full closest-point search.
  SphereQueryCounters near_r;
  SphereQueryCounters full;
  const Vec3 p(0.07, 0.001, 0.002);
  EXPECT_FALSE(tree.contact_within_counted(p, 0.001, nullptr, nullptr, &near_r));
  (void)tree.closest_point_counted(p, nullptr, &full);
  EXPECT_EQ(near_r.triangles_tested, 0U);
  EXPECT_LT(near_r.nodes_visited, full.nodes_visited);
}

// Smooth bump of height `h` around direction `axis` on a body centred at the origin.
void bulge(TriangleMesh& mesh, const Vec3& axis, double h, double width_rad) {
  for (Vec3& v : mesh.vertices) {
    const double angle = std::acos(std::clamp(v.normalized().dot(axis), -1.0, 1.0));
    v += h * std::exp(-(angle * angle) / (width_rad * width_rad)) * v.normalized();
  }
}

TEST(SphereTree, RefitAfterBulgeKeepsInvariantsAndExactAnswers) {
  TriangleMesh mesh = make_bumpy_sphere(13500);
  SphereTree tree(mesh);
  const double root_before = tree.node_sphere(0).radius;
  bulge(mesh, Vec3(1, 1, 0).normalized(), 0.02, 0.4);

  // Before refit the moved corners poke out of their leaves: the refit below is what fixes it.
  std::size_t poking = 0;
  for (std::size_t leaf = 0; leaf < tree.leaf_count(); ++leaf) {
    const Sphere s = tree.node_sphere(tree.leaf_node(leaf));
    for (std::uint32_t t : tree.leaf_triangles(leaf)) {
      for (const Vec3& v : mesh.corners(t)) {
        poking += (v - s.center).norm() > s.radius * (1.0 + kContainTol) ? 1 : 0;
      }
    }
  }
  EXPECT_GT(poking, 100U);

  tree.refit();
  check_invariants(tree, 4);
  EXPECT_GT(tree.node_sphere(0).radius, root_before);  // the bulge reaches past the old root
  std::vector<Vec3> pts = sample_points(mesh, 600, 0.004, 31);
  for (const Vec3& p : trajectory(mesh, 300, 3)) {
    pts.push_back(p);
  }
  QueryHint hint;
  for (const Vec3& p : pts) {
    const SurfacePoint want = brute_force(tree, p);
    expect_same_answer(tree.closest_point(p), want, p);
    expect_same_answer(tree.closest_point(p, &hint), want, p);
  }
}

TEST(SphereTree, RefitAfterDentInSheetKeepsInvariantsAndExactAnswers) {
  TriangleMesh sheet = make_sheet(61, 0.2);
  SphereTree tree(sheet, {4, 4, {}});
  // Push a 15 mm deep, 3 cm wide dent into the sheet (a ball pressing on it).
  for (Vec3& v : sheet.vertices) {
    const double r2 = v.x() * v.x() + v.y() * v.y();
    v.z() -= 0.015 * std::exp(-r2 / (0.03 * 0.03));
  }
  tree.refit();
  check_invariants(tree, 4);
  // Above the dent, the closest point is inside the dent and is above it (outside side, +z).
  const SurfacePoint centre = tree.closest_point(Vec3(0, 0, 0.001));
  EXPECT_GT(centre.signed_distance, 0.014);
  EXPECT_LE(centre.signed_distance, 0.016 + 1e-12);
  EXPECT_LT(centre.point.z(), -0.013);
  for (const Vec3& p : sample_points(sheet, 600, 0.003, 41)) {
    expect_same_answer(tree.closest_point(p), brute_force(tree, p), p);
    const double d = std::abs(brute_force(tree, p).signed_distance);
    SurfacePoint out;
    EXPECT_EQ(tree.contact_within(p, 0.002, &out), d <= 0.002);
  }
}

// Brute force: every leaf of `a` against every leaf of `b`.
std::set<std::pair<std::uint32_t, std::uint32_t>> all_pairs(const SphereTree& a,
                                                            const SphereTree& b,
                                                            const Iso3& X_a_b) {
  std::set<std::pair<std::uint32_t, std::uint32_t>> pairs;
  for (std::uint32_t la = 0; la < a.leaf_count(); ++la) {
    const Sphere sa = a.node_sphere(a.leaf_node(la));
    for (std::uint32_t lb = 0; lb < b.leaf_count(); ++lb) {
      const Sphere sb = b.node_sphere(b.leaf_node(lb));
      const double reach = sa.radius + sb.radius;
      if ((sa.center - X_a_b * sb.center).squaredNorm() <= reach * reach) {
        pairs.insert({la, lb});
      }
    }
  }
  return pairs;
}

TEST(SphereTree, TreeVsTreeEqualsAllPairsWithFewerTests) {
  const TriangleMesh ball = make_bumpy_sphere(3000, 0.03);
  const TriangleMesh sheet = make_sheet(41, 0.2);
  const SphereTree tree_ball(ball);
  const SphereTree tree_sheet(sheet);
  Iso3 X_sheet_ball = Iso3::Identity();
  X_sheet_ball.rotate(Eigen::AngleAxisd(0.7, Vec3(1, 2, 3).normalized()));
  X_sheet_ball.translation() = Vec3(0.01, -0.02, 0.025);  // ball sunk 5 mm into the sheet

  std::vector<LeafPair> out;
  out.reserve(4096);
  TreeTraversalCounters counters;
  tree_sheet.overlapping_leaves(tree_ball, X_sheet_ball, out, &counters);
  std::set<std::pair<std::uint32_t, std::uint32_t>> got;
  for (const LeafPair& lp : out) {
    EXPECT_TRUE(got.insert({lp.leaf_a, lp.leaf_b}).second) << "duplicate pair";
  }
  const auto want = all_pairs(tree_sheet, tree_ball, X_sheet_ball);
  EXPECT_FALSE(want.empty());
  EXPECT_EQ(got, want);
  const std::size_t all = tree_sheet.leaf_count() * tree_ball.leaf_count();
  EXPECT_LT(counters.sphere_tests, all / 20);

  // The other way round (inverse transform) gives the mirrored set.
  std::vector<LeafPair> back;
  TreeTraversalCounters counters_back;
  tree_ball.overlapping_leaves(tree_sheet, X_sheet_ball.inverse(), back, &counters_back);
  std::set<std::pair<std::uint32_t, std::uint32_t>> mirrored;
  for (const LeafPair& lp : back) {
    mirrored.insert({lp.leaf_b, lp.leaf_a});
  }
  EXPECT_EQ(mirrored, want);

  // Lifted clear of the sheet: nothing, after one root test.
  X_sheet_ball.translation().z() = 0.5;
  std::vector<LeafPair> none;
  TreeTraversalCounters counters_none;
  tree_sheet.overlapping_leaves(tree_ball, X_sheet_ball, none, &counters_none);
  EXPECT_TRUE(none.empty());
  EXPECT_EQ(counters_none.sphere_tests, 1U);
}

// With a margin, the pairs cover every vertex of one mesh that lies within the margin of the other
// surface (inside or out): what body contact relies on to find vertices that touch or sink in.
TEST(SphereTree, TreeVsTreeMarginCoversEveryVertexNearTheOtherSurface) {
  const TriangleMesh ball = make_bumpy_sphere(3000, 0.03);
  const TriangleMesh sheet = make_sheet(41, 0.2);
  const SphereTree tree_ball(ball);
  const SphereTree tree_sheet(sheet);
  Iso3 X_sheet_ball = Iso3::Identity();
  X_sheet_ball.rotate(Eigen::AngleAxisd(0.4, Vec3(2, -1, 1).normalized()));
  X_sheet_ball.translation() = Vec3(-0.01, 0.015, 0.028);  // sunk 2 mm
  const double margin_m = 0.004;

  std::vector<LeafPair> out;
  TreeTraversalCounters counters;
  EXPECT_TRUE(tree_sheet.overlapping_leaves(tree_ball, X_sheet_ball, out, &counters, margin_m));
  std::set<std::uint32_t> covered;  // ball vertices in some pair's ball leaf
  for (const LeafPair& lp : out) {
    for (const std::uint32_t t : tree_ball.leaf_triangles(lp.leaf_b)) {
      for (const std::uint32_t v : ball.triangles[t]) {
        covered.insert(v);
      }
    }
  }
  std::size_t near = 0;
  for (std::uint32_t v = 0; v < ball.vertices.size(); ++v) {
    const SurfacePoint sp = tree_sheet.closest_point(X_sheet_ball * ball.vertices[v]);
    if (std::abs(sp.signed_distance) <= margin_m) {
      ++near;
      EXPECT_TRUE(covered.count(v) == 1) << "vertex " << v << " at " << sp.signed_distance;
    }
  }
  EXPECT_GT(near, 20U);
  // Far fewer tests than all leaf pairs, and the margin only adds pairs.
  EXPECT_LT(counters.sphere_tests, tree_sheet.leaf_count() * tree_ball.leaf_count() / 20);
  std::vector<LeafPair> tight;
  tree_sheet.overlapping_leaves(tree_ball, X_sheet_ball, tight);
  EXPECT_LT(tight.size(), out.size());

  // A cap stops the descent and says so.
  std::vector<LeafPair> capped;
  EXPECT_FALSE(
      tree_sheet.overlapping_leaves(tree_ball, X_sheet_ball, capped, nullptr, margin_m, 10));
  EXPECT_EQ(capped.size(), 10U);
}

TEST(SphereTree, TreeVsTreeTwoBodiesAfterRefit) {
  TriangleMesh a = make_bumpy_sphere(2000, 0.04);
  const TriangleMesh b = make_uv_sphere(0.02, 20, 10);
  SphereTree tree_a(a, {3, 2, {}});
  const SphereTree tree_b(b, {5, 3, {}});
  bulge(a, Vec3::UnitX(), 0.01, 0.5);
  tree_a.refit();
  Iso3 X_a_b = Iso3::Identity();
  X_a_b.translation() = Vec3(0.065, 0.002, -0.001);  // against the bulge
  std::vector<LeafPair> out;
  TreeTraversalCounters counters;
  tree_a.overlapping_leaves(tree_b, X_a_b, out, &counters);
  std::set<std::pair<std::uint32_t, std::uint32_t>> got;
  for (const LeafPair& lp : out) {
    got.insert({lp.leaf_a, lp.leaf_b});
  }
  const auto want = all_pairs(tree_a, tree_b, X_a_b);
  EXPECT_FALSE(want.empty());
  EXPECT_EQ(got, want);
  EXPECT_LT(counters.sphere_tests, tree_a.leaf_count() * tree_b.leaf_count());
}

}  // namespace
}  // namespace hapsim
