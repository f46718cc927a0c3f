#include "hapsim/deform/vertex_deflection.h"

#include "hapsim/core/error.h"
#include "hapsim/deform/point_hash_grid.h"
#include "hapsim/geometry/procedural.h"

#include "support/allocation_counter.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <cstdlib>
#include <limits>
#include <new>
#include <numbers>
#include <random>
#include <set>
#include <vector>

namespace hapsim {
namespace {

// Eq. 1 written out independently.
double eq1(double d, double x, double d0) {
  return d < d0 ? x / 2.0 * (std::cos(std::numbers::pi * d / d0) + 1.0) : 0.0;
}

// 1 mm grid, 101×101 nodes over 0.1 m, normals +z, so the default direction is −z.
TriangleMesh flat_patch() {
  return make_sheet(101, 0.1);
}

double planar_distance(const Vec3& a, const Vec3& b) {
  return (a - b).norm();
}

TEST(VertexDeflection, ProfileMatchesEquationOne) {
  const double x = 0.003, d0 = 0.012;
  EXPECT_DOUBLE_EQ(VertexDeflection::deflection_profile_m(0.0, x, d0), x);
  EXPECT_NEAR(VertexDeflection::deflection_profile_m(d0 / 2, x, d0), x / 2, 1e-18);
  EXPECT_EQ(VertexDeflection::deflection_profile_m(d0, x, d0), 0.0);
  EXPECT_EQ(VertexDeflection::deflection_profile_m(2 * d0, x, d0), 0.0);
  EXPECT_NEAR(VertexDeflection::deflection_profile_m(d0 * (1 - 1e-9), x, d0), 0.0, 1e-18);
  double previous = kInf;
  for (int k = 0; k <= 1000; ++k) {
    const double d = d0 * k / 1000.0;
    const double delta = VertexDeflection::deflection_profile_m(d, x, d0);
    EXPECT_NEAR(delta, eq1(d, x, d0), 1e-18);
    EXPECT_LE(delta, previous);
    EXPECT_GE(delta, 0.0);
    previous = delta;
  }
  EXPECT_DOUBLE_EQ(VertexDeflection::zero_deflection_distance_m(0.002, 0.008, 1.5), 0.015);
}

// step() evaluates eq. 1 from the squared distance by a power series (no sqrt, no cos): within
// 1e-10·x everywhere, exact at the centre, zero from d0 on, never negative.
TEST(VertexDeflection, SeriesProfileMatchesEquationOne) {
  const double x = 0.011, d0 = 0.027;
  EXPECT_EQ(VertexDeflection::deflection_profile_from_squared_m(0.0, x, d0), x);
  EXPECT_EQ(VertexDeflection::deflection_profile_from_squared_m(d0 * d0, x, d0), 0.0);
  EXPECT_EQ(VertexDeflection::deflection_profile_from_squared_m(-1.0, x, d0), 0.0);
  EXPECT_EQ(VertexDeflection::deflection_profile_from_squared_m(1e-6, 0.0, d0), 0.0);
  double worst = 0.0;
  for (int k = 0; k <= 100000; ++k) {
    const double d = d0 * k / 100000.0;
    const double series = VertexDeflection::deflection_profile_from_squared_m(d * d, x, d0);
    worst = std::max(worst, std::abs(series - eq1(d, x, d0)));
    EXPECT_GE(series, 0.0);
  }
  EXPECT_LT(worst, 1e-10 * x);
  // The series is not an exact copy of cos: it does differ somewhere (so this test can fail).
  EXPECT_GT(worst, 0.0);
}

// Holding a press (the same contacts again) skips recomputing its targets; the result must be
// what a full recomputation gives. The reference sees the held contact twice in its list every
// other step (same targets, but never "the same contacts as last step", so never skipped).
TEST(VertexDeflection, HeldPressGivesWhatFullRecomputationGives) {
  VertexDeflectionOptions options;
  options.segments = {{.recovery_time_constant_s = 0.02}};
  VertexDeflection held(flat_patch(), options);
  VertexDeflection reference(flat_patch(), options);
  const DeflectionContact a{Vec3(-0.01, 0.0, 0.0), 0.003, 0.005, 0};
  const DeflectionContact b{Vec3(0.012, 0.002, 0.0), 0.002, 0.004, 0};
  const DeflectionContact b_deeper{Vec3(0.012, 0.002, 0.0), 0.0025, 0.004, 0};
  std::vector<std::vector<DeflectionContact>> script;
  const auto add = [&](int steps, std::vector<DeflectionContact> contacts) {
    script.insert(script.end(), static_cast<std::size_t>(steps), contacts);
  };
  add(20, {a});        // press a
  add(60, {b});        // hold b while a recovers
  add(5, {b_deeper});  // press b deeper, hold
  add(30, {b});        // shallower: b recovers to b
  add(300, {});        // release all: back to rest
  std::size_t held_steps_with_motion = 0;
  for (std::size_t k = 0; k < script.size(); ++k) {
    SCOPED_TRACE(k);
    held.step(script[k], 1e-3);
    std::vector<DeflectionContact> twice = script[k];
    if (k % 2 == 1 && !twice.empty()) {
      twice.push_back(twice.front());
    }
    reference.step(twice, 1e-3);
    ASSERT_EQ(held.mesh().vertices, reference.mesh().vertices);
    const std::set<std::uint32_t> m1(held.moved_vertices().begin(), held.moved_vertices().end());
    const std::set<std::uint32_t> m2(reference.moved_vertices().begin(),
                                     reference.moved_vertices().end());
    ASSERT_EQ(m1, m2);
    const std::set<std::uint32_t> t1(held.moved_triangles().begin(), held.moved_triangles().end());
    const std::set<std::uint32_t> t2(reference.moved_triangles().begin(),
                                     reference.moved_triangles().end());
    ASSERT_EQ(t1, t2);
    ASSERT_EQ(held.max_deflection_m(), reference.max_deflection_m());
    ASSERT_EQ(held.deformed_vertex_count(), reference.deformed_vertex_count());
    held_steps_with_motion += (k >= 21 && k < 80 && !m1.empty()) ? 1 : 0;
  }
  // While b is held, a's dent is still recovering: held steps do move vertices.
  EXPECT_GT(held_steps_with_motion, 20u);
  for (std::uint32_t v = 0; v < held.rest_positions().size(); ++v) {
    ASSERT_EQ(held.mesh().vertices[v], held.rest_positions()[v]);
  }
}

TEST(VertexDeflection, OneContactMovesExactlyTheVerticesWithinD0) {
  VertexDeflectionOptions options;
  options.segments = {{.elasticity_factor = 1.5}};
  VertexDeflection deflection(flat_patch(), options);
  const Vec3 p(0.0013, -0.0021, 0.0);
  const double x = 0.002, r = 0.005, d0 = (x + r) * 1.5;
  const DeflectionContact c{p, x, r, 0};
  deflection.step({&c, 1}, 1e-3);

  std::set<std::uint32_t> expected_moved;
  const auto rest = deflection.rest_positions();
  for (std::uint32_t v = 0; v < rest.size(); ++v) {
    const double d = planar_distance(rest[v], p);
    const Vec3 expected = rest[v] - Vec3::UnitZ() * eq1(d, x, d0);
    EXPECT_NEAR((deflection.mesh().vertices[v] - expected).norm(), 0.0, 1e-15) << v;
    if (d >= d0) {
      EXPECT_EQ(deflection.mesh().vertices[v], rest[v]) << "vertex beyond d0 moved: " << v;
    } else if (eq1(d, x, d0) > 0.0) {
      expected_moved.insert(v);
    }
  }
  // d0 = 10.5 mm on a 1 mm grid: about π·10.5² ≈ 346 vertices.
  EXPECT_GT(expected_moved.size(), 300u);
  EXPECT_LT(expected_moved.size(), 400u);
  const std::set<std::uint32_t> moved(deflection.moved_vertices().begin(),
                                      deflection.moved_vertices().end());
  EXPECT_EQ(moved.size(), deflection.moved_vertices().size());  // each once
  EXPECT_EQ(moved, expected_moved);
  EXPECT_EQ(deflection.deformed_vertex_count(), expected_moved.size());
  double deepest = 0.0;
  for (const Vec3& q : rest) {
    deepest = std::max(deepest, eq1(planar_distance(q, p), x, d0));
  }
  EXPECT_GT(deepest, 0.99 * x);  // a node lies within 0.5 mm of p
  EXPECT_NEAR(deflection.max_deflection_m(), deepest, 1e-18);

  // Moved triangles = exactly the triangles with a moved corner.
  std::set<std::uint32_t> expected_tris;
  const TriangleMesh& m = deflection.mesh();
  for (std::uint32_t t = 0; t < m.triangle_count(); ++t) {
    for (const auto v : m.triangles[t]) {
      if (moved.count(v) != 0) {
        expected_tris.insert(t);
      }
    }
  }
  const std::set<std::uint32_t> tris(deflection.moved_triangles().begin(),
                                     deflection.moved_triangles().end());
  EXPECT_EQ(tris.size(), deflection.moved_triangles().size());
  EXPECT_EQ(tris, expected_tris);

  // Normals are left to update_normals() (display rate); then they match a full recomputation.
  const std::uint32_t centre = 50 * 101 + 50, right = centre + 5;  // (0, 0) and (5 mm, 0)
  EXPECT_EQ(m.vertex_normals[right], Vec3::UnitZ());  // moved, but the normal is still stale
  deflection.update_normals();
  EXPECT_LT(m.vertex_normals[right].x(), -1e-2);  // right of the dent, tilted towards it
  // Inside a dent the surface normal leans towards the dent's axis (p = (1.3, −2.1) mm): at the
  // centre node x > 0 and y < 0. Independently, from the smooth surface z = −δ(d):
  // n ∝ (δ'(d)·(q − p)/d, 1) with δ'(d) = −(x/2)(π/d0)·sin(π·d/d0).
  {
    const Vec3 q = rest[centre];
    const double d = planar_distance(q, p);
    const double slope = -x / 2.0 * std::numbers::pi / d0 * std::sin(std::numbers::pi * d / d0);
    const Vec3 smooth =
        Vec3(slope * (q.x() - p.x()) / d, slope * (q.y() - p.y()) / d, 1.0).normalized();
    EXPECT_GT(m.vertex_normals[centre].x(), 1e-2);
    EXPECT_LT(m.vertex_normals[centre].y(), -1e-2);
    // 1 mm grid vs the smooth dent (d0 = 10.5 mm): within 0.01 per component.
    EXPECT_NEAR((m.vertex_normals[centre] - smooth).norm(), 0.0, 1e-2)
        << m.vertex_normals[centre].transpose() << " vs " << smooth.transpose();
  }
  TriangleMesh copy = m;
  copy.compute_vertex_normals();
  for (std::uint32_t v = 0; v < m.vertex_count(); ++v) {
    EXPECT_NEAR((m.vertex_normals[v] - copy.vertex_normals[v]).norm(), 0.0, 1e-12) << v;
  }
}

// step() keeps offsets only; mesh() writes the positions of what moved since it was last asked,
// exactly rest + offset·direction (position(v)), and a released surface is exactly the rest.
TEST(VertexDeflection, PositionsAreWrittenWhenTheMeshIsAsked) {
  VertexDeflection deflection(flat_patch());
  const std::vector<Vec3>& vertices = deflection.mesh().vertices;  // the array, held
  const auto rest = deflection.rest_positions();
  const DeflectionContact c{Vec3(0.001, 0.0, 0.0), 0.003, 0.004, 0};
  for (int k = 0; k < 3; ++k) {
    deflection.step({&c, 1}, 1e-3);
  }
  ASSERT_GT(deflection.deformed_vertex_count(), 100u);
  // Nobody asked: the haptic path left the display positions alone.
  for (std::uint32_t v = 0; v < rest.size(); ++v) {
    ASSERT_EQ(vertices[v], rest[v]) << v;
  }
  const TriangleMesh& mesh = deflection.mesh();
  std::size_t moved = 0;
  for (std::uint32_t v = 0; v < rest.size(); ++v) {
    ASSERT_EQ(mesh.vertices[v], deflection.position(v)) << v;
    ASSERT_EQ(mesh.vertices[v],
              deflection.deflection_m(v) > 0.0
                  ? Vec3(rest[v] + deflection.deflection_m(v) * deflection.directions()[v])
                  : rest[v]);
    moved += mesh.vertices[v] != rest[v] ? 1 : 0;
  }
  EXPECT_EQ(moved, deflection.deformed_vertex_count());
  for (int k = 0; k < 2000 && deflection.deformed_vertex_count() > 0; ++k) {
    deflection.step({}, 1e-3);
    if (k % 97 == 0) {
      (void)deflection.mesh();  // asked now and then while it recovers
    }
  }
  ASSERT_EQ(deflection.deformed_vertex_count(), 0u);
  EXPECT_EQ(deflection.mesh().vertices, std::vector<Vec3>(rest.begin(), rest.end()));
}

// Contacts whose reaches overlap share one pass over the grid; each vertex gets exactly the
// deepest of what each contact alone gives it (the same bits), whatever the order.
TEST(VertexDeflection, OverlappingContactsGiveTheDeepestOfEachAlone) {
  VertexDeflectionOptions options;
  options.segments = {{.elasticity_factor = 1.5, .max_deflection_m = 0.015}};
  std::vector<DeflectionContact> fingers;
  for (int f = 0; f < 5; ++f) {
    fingers.push_back(
        {Vec3(-0.03 + 0.015 * f, 0.002 * f, 0.0), 0.004 + 0.001 * (f % 3), 0.006 + 0.0005 * f, 0});
  }
  fingers.push_back({Vec3(0.045, 0.045, 0.0), 0.002, 0.003, 0});  // far away: its own pass
  VertexDeflection together(flat_patch(), options);
  together.step(fingers, 1e-3);
  std::reverse(fingers.begin(), fingers.end());
  VertexDeflection reversed(flat_patch(), options);
  reversed.step(fingers, 1e-3);
  std::vector<double> deepest(101 * 101, 0.0);
  for (const DeflectionContact& c : fingers) {
    VertexDeflection alone(flat_patch(), options);
    alone.step({&c, 1}, 1e-3);
    for (std::uint32_t v = 0; v < deepest.size(); ++v) {
      deepest[v] = std::max(deepest[v], alone.deflection_m(v));
    }
  }
  std::size_t reached = 0;
  for (std::uint32_t v = 0; v < deepest.size(); ++v) {
    ASSERT_EQ(together.deflection_m(v), deepest[v]) << v;
    ASSERT_EQ(reversed.deflection_m(v), deepest[v]) << v;
    reached += deepest[v] > 0.0 ? 1 : 0;
  }
  EXPECT_EQ(together.deformed_vertex_count(), reached);
  EXPECT_GT(reached, 3000u);
}

TEST(VertexDeflection, RepeatedContactDoesNotDrift) {
  VertexDeflection deflection(flat_patch());
  const DeflectionContact c{Vec3(0.0, 0.0, 0.0), 0.002, 0.004, 0};
  deflection.step({&c, 1}, 1e-3);
  const std::vector<Vec3> first = deflection.mesh().vertices;
  for (int k = 0; k < 500; ++k) {
    deflection.step({&c, 1}, 1e-3);
  }
  EXPECT_EQ(deflection.mesh().vertices, first);
  EXPECT_TRUE(deflection.moved_vertices().empty());  // nothing changed: nothing to refit
}

TEST(VertexDeflection, RadialDirectionsMoveTowardsCentroid) {
  const double radius = 0.05;
  TriangleMesh sphere = make_uv_sphere(radius, 48, 24);
  VertexDeflectionOptions options;
  for (const Vec3& v : sphere.vertices) {
    options.directions.push_back(
        -v);  // towards the centroid at the origin (unnormalised on purpose)
  }
  VertexDeflection deflection(sphere, options);
  const Vec3 p = radius * Vec3(1.0, 1.0, 0.5).normalized();
  const double x = 0.004, r = 0.006, d0 = (x + r) * 1.5;
  const DeflectionContact c{p, x, r, 0};
  deflection.step({&c, 1}, 1e-3);
  int moved = 0;
  for (std::uint32_t v = 0; v < sphere.vertex_count(); ++v) {
    const Vec3& q = deflection.mesh().vertices[v];
    const double delta = eq1((sphere.vertices[v] - p).norm(), x, d0);
    EXPECT_NEAR(q.norm(), radius - delta, 1e-12);
    EXPECT_NEAR((q.normalized() - sphere.vertices[v].normalized()).norm(), 0.0, 1e-12);
    moved += delta > 0.0 ? 1 : 0;
  }
  EXPECT_GT(moved, 5);
}

TEST(VertexDeflection, DeepestDeflectionWins) {
  VertexDeflection deflection(flat_patch());
  const std::vector<DeflectionContact> contacts{{Vec3(-0.004, 0.0, 0.0), 0.002, 0.004, 0},
                                                {Vec3(0.005, 0.001, 0.0), 0.003, 0.003, 0}};
  deflection.step(contacts, 1e-3);
  const double f = DeflectionParams{}.elasticity_factor;
  int both = 0;
  for (std::uint32_t v = 0; v < deflection.rest_positions().size(); ++v) {
    const Vec3& q = deflection.rest_positions()[v];
    const double a = eq1((q - contacts[0].p_mesh).norm(), 0.002, 0.006 * f);
    const double b = eq1((q - contacts[1].p_mesh).norm(), 0.003, 0.006 * f);
    EXPECT_NEAR(deflection.deflection_m(v), std::max(a, b), 1e-10 * 0.003);  // step's series
    both += (a > 0.0 && b > 0.0) ? 1 : 0;
  }
  EXPECT_GT(both, 10);  // the footprints overlap, so the rule is exercised
}

TEST(VertexDeflection, ContactDeflectsOnlyItsSegment) {
  TriangleMesh mesh = flat_patch();
  VertexDeflectionOptions options;
  options.segments = {DeflectionParams{}, DeflectionParams{.elasticity_factor = 0.5}};
  for (const Vec3& v : mesh.vertices) {
    options.segment_of_vertex.push_back(v.x() < 0.0 ? 0u : 1u);
  }
  VertexDeflection deflection(mesh, options);
  const DeflectionContact c{Vec3::Zero(), 0.002, 0.004, 1};
  deflection.step({&c, 1}, 1e-3);
  int moved = 0;
  for (std::uint32_t v = 0; v < mesh.vertex_count(); ++v) {
    const Vec3& q = mesh.vertices[v];
    const double expected = q.x() < 0.0 ? 0.0 : eq1(q.norm(), 0.002, 0.006 * 0.5);
    EXPECT_NEAR(deflection.deflection_m(v), expected, 1e-10 * 0.002);  // step's series
    moved += expected > 0.0 ? 1 : 0;
  }
  EXPECT_GT(moved, 10);
}

TEST(VertexDeflection, RecoversExponentiallyWithoutOvershoot) {
  const double tau = 0.05, dt = 1e-3;
  VertexDeflectionOptions options;
  options.segments = {{.recovery_time_constant_s = tau, .rest_tolerance_m = 1e-7}};
  VertexDeflection deflection(flat_patch(), options);
  const std::uint32_t centre = 50 * 101 + 50;
  const DeflectionContact c{deflection.rest_positions()[centre], 0.003, 0.004, 0};
  deflection.step({&c, 1}, dt);
  ASSERT_DOUBLE_EQ(deflection.deflection_m(centre), 0.003);
  std::vector<double> previous(deflection.rest_positions().size());
  for (std::uint32_t v = 0; v < previous.size(); ++v) {
    previous[v] = deflection.deflection_m(v);
  }
  // Bound: 0.003·e^{−k·dt/τ} < 1e-7 after k > τ/dt·ln(3e4) ≈ 516 steps.
  const int bound = static_cast<int>(std::ceil(tau / dt * std::log(0.003 / 1e-7))) + 1;
  int steps = 0;
  for (; steps < 10 * bound && deflection.deformed_vertex_count() > 0; ++steps) {
    deflection.step({}, dt);
    for (std::uint32_t v = 0; v < previous.size(); ++v) {
      const double now = deflection.deflection_m(v);
      ASSERT_GE(now, 0.0);          // never past rest
      ASSERT_LE(now, previous[v]);  // never back out
      previous[v] = now;
    }
    if (steps == 9) {  // after 10 steps: exactly the exponential law
      EXPECT_NEAR(deflection.deflection_m(centre), 0.003 * std::exp(-10 * dt / tau), 1e-15);
    }
  }
  EXPECT_LE(steps, bound);
  EXPECT_GE(steps, bound - 2);  // not faster than configured either
  EXPECT_EQ(deflection.mesh().vertices, std::vector<Vec3>(deflection.rest_positions().begin(),
                                                          deflection.rest_positions().end()));
  EXPECT_EQ(deflection.max_deflection_m(), 0.0);
}

TEST(VertexDeflection, RecoversAtCappedSpeed) {
  const double speed = 0.01, dt = 1e-3;  // 10 µm per step
  VertexDeflectionOptions options;
  options.segments = {{.recovery_time_constant_s = 0.0,
                       .max_recovery_speed_m_per_s = speed,
                       .rest_tolerance_m = 1e-7}};
  VertexDeflection deflection(flat_patch(), options);
  const std::uint32_t centre = 50 * 101 + 50;
  const DeflectionContact c{deflection.rest_positions()[centre], 0.00105, 0.004, 0};
  deflection.step({&c, 1}, dt);
  deflection.step({}, dt);
  EXPECT_NEAR(deflection.deflection_m(centre), 0.00104, 1e-15);
  int steps = 1;
  while (deflection.deformed_vertex_count() > 0 && steps < 1000) {
    deflection.step({}, dt);
    ++steps;
  }
  EXPECT_EQ(steps, 105);  // 1.05 mm at 10 µm per step
  EXPECT_EQ(deflection.mesh().vertices[centre], deflection.rest_positions()[centre]);
}

TEST(VertexDeflection, MovingContactPressesNewAndReleasesOld) {
  VertexDeflection deflection(flat_patch());
  const DeflectionContact a{Vec3(-0.02, 0.0, 0.0), 0.002, 0.003, 0};
  const DeflectionContact b{Vec3(0.02, 0.0, 0.0), 0.002, 0.003, 0};
  deflection.step({&a, 1}, 1e-3);
  const std::uint32_t va = 50 * 101 + 30, vb = 50 * 101 + 70;
  EXPECT_DOUBLE_EQ(deflection.deflection_m(va), 0.002);
  deflection.step({&b, 1}, 1e-3);
  EXPECT_DOUBLE_EQ(deflection.deflection_m(vb), 0.002);  // pressed at once
  EXPECT_NEAR(deflection.deflection_m(va), 0.002 * std::exp(-1e-3 / 0.1), 1e-15);  // recovering
}

TEST(VertexDeflection, ResetReturnsToRest) {
  VertexDeflection deflection(flat_patch());
  const DeflectionContact c{Vec3::Zero(), 0.002, 0.003, 0};
  deflection.step({&c, 1}, 1e-3);
  const std::size_t deformed = deflection.deformed_vertex_count();
  ASSERT_GT(deformed, 0u);
  deflection.update_normals();
  deflection.reset();
  deflection.update_normals();
  EXPECT_EQ(deflection.moved_vertices().size(), deformed);
  EXPECT_EQ(deflection.deformed_vertex_count(), 0u);
  for (std::uint32_t v = 0; v < deflection.rest_positions().size(); ++v) {
    EXPECT_EQ(deflection.mesh().vertices[v], deflection.rest_positions()[v]);
    EXPECT_NEAR((deflection.mesh().vertex_normals[v] - Vec3::UnitZ()).norm(), 0.0, 1e-12);
  }
}

// The automatic grid cell: twice the mean edge, or half a typical press's d0 when that is
// larger, so a 25 mm dent on a 1 mm mesh looks up ~5^3 cells, not ~20^3. The deflection itself
// does not depend on the cell (same vertices, same values).
TEST(VertexDeflection, GridCellFollowsTheTypicalDent) {
  const TriangleMesh patch = flat_patch();  // 1 mm grid: mean edge (1 + 1 + sqrt 2) / 3 mm
  const double mean_edge = (2.0 + std::sqrt(2.0)) / 3.0 * 1e-3;
  VertexDeflectionOptions bone;
  bone.segments = {{.elasticity_factor = 0.3, .max_deflection_m = 0.0005}};
  bone.typical_contact_radius_m = 0.007;
  EXPECT_NEAR(VertexDeflection(patch, bone).grid().cell_m(), 2.0 * mean_edge, 1e-9);
  VertexDeflectionOptions muscle;
  muscle.segments = {{.elasticity_factor = 1.5, .max_deflection_m = 0.015}};
  muscle.typical_contact_radius_m = 0.007;
  VertexDeflection wide(patch, muscle);
  EXPECT_NEAR(wide.grid().cell_m(), 0.5 * 1.5 * (0.010 + 0.007), 1e-12);
  muscle.grid_cell_m = 0.001;  // given explicitly: used as is
  VertexDeflection fine(patch, muscle);
  EXPECT_EQ(fine.grid().cell_m(), 0.001);
  const DeflectionContact c{Vec3(0.0013, -0.0021, 0.0), 0.009, 0.007, 0};
  wide.step({&c, 1}, 1e-3);
  fine.step({&c, 1}, 1e-3);
  EXPECT_EQ(wide.mesh().vertices, fine.mesh().vertices);
  EXPECT_GT(wide.deformed_vertex_count(), 1000u);
}

TEST(VertexDeflection, NoAllocationPerStep) {
  VertexDeflection deflection(flat_patch());
  std::vector<DeflectionContact> contacts{{Vec3(-0.01, 0.0, 0.0), 0.003, 0.005, 0},
                                          {Vec3(0.01, 0.0, 0.0), 0.002, 0.004, 0}};
  const Vec3* vertices = deflection.mesh().vertices.data();
  const std::uint32_t* moved = deflection.moved_vertices().data();
  deflection.step(contacts, 1e-3);  // warm-up (first touch of every buffer)
  const long before = test::allocation_count();
  for (int k = 0; k < 2000; ++k) {
    contacts[0].p_mesh.x() = -0.04 + 4e-5 * k;  // sweeps: presses and recoveries every step
    deflection.step(k % 3 == 0 ? std::span<const DeflectionContact>() : contacts, 1e-3);
    if (k % 16 == 0) {
      deflection.update_normals();
    }
  }
  deflection.reset();
  const long after = test::allocation_count();
  EXPECT_EQ(after - before, 0);
  EXPECT_EQ(deflection.mesh().vertices.data(), vertices);
  EXPECT_EQ(deflection.moved_vertices().data(), moved);
  // The counter itself works (otherwise the check above could not fail).
  auto* probe = new int(1);
  EXPECT_GT(test::allocation_count(), after);
  delete probe;
}

TEST(VertexDeflection, BadParametersThrow) {
  const double nan = std::numeric_limits<double>::quiet_NaN();
  const auto with = [](DeflectionParams p) {
    VertexDeflectionOptions o;
    o.segments = {p};
    return o;
  };
  EXPECT_THROW(VertexDeflection(flat_patch(), with({.elasticity_factor = -1.0})), Error);
  EXPECT_THROW(VertexDeflection(flat_patch(), with({.elasticity_factor = 0.0})), Error);
  EXPECT_THROW(VertexDeflection(flat_patch(), with({.recovery_time_constant_s = -0.1})), Error);
  EXPECT_THROW(VertexDeflection(flat_patch(), with({.recovery_time_constant_s = nan})), Error);
  EXPECT_THROW(VertexDeflection(flat_patch(), with({.max_recovery_speed_m_per_s = 0.0})), Error);
  EXPECT_THROW(VertexDeflection(flat_patch(), with({.max_deflection_m = -0.01})), Error);
  VertexDeflectionOptions wrong_size;
  wrong_size.directions = {Vec3::UnitZ()};
  EXPECT_THROW(VertexDeflection(flat_patch(), wrong_size), Error);
  VertexDeflectionOptions zero_dir;
  zero_dir.directions.assign(101 * 101, Vec3::UnitZ());
  zero_dir.directions[7] = Vec3::Zero();
  EXPECT_THROW(VertexDeflection(flat_patch(), zero_dir), Error);
  VertexDeflectionOptions bad_segment;
  bad_segment.segment_of_vertex.assign(101 * 101, 1u);  // only segment 0 exists
  EXPECT_THROW(VertexDeflection(flat_patch(), bad_segment), Error);
  TriangleMesh nan_mesh = flat_patch();
  nan_mesh.vertices[3].x() = nan;
  EXPECT_THROW(VertexDeflection(std::move(nan_mesh)), Error);
  EXPECT_THROW(PointHashGrid(std::vector<Vec3>{Vec3::Zero()}, -1.0), Error);
}

TEST(VertexDeflection, BadContactsNeverGiveNaN) {
  const double nan = std::numeric_limits<double>::quiet_NaN();
  const double inf = std::numeric_limits<double>::infinity();
  VertexDeflectionOptions options;
  options.segments = {{.max_deflection_m = 0.005}};
  VertexDeflection deflection(flat_patch(), options);
  const std::vector<DeflectionContact> contacts{
      {Vec3(nan, 0.0, 0.0), 0.002, 0.003, 0},   // rejected
      {Vec3::Zero(), nan, 0.003, 0},            // rejected
      {Vec3::Zero(), 0.002, nan, 0},            // rejected
      {Vec3::Zero(), 0.002, 0.003, 9},          // no such segment: rejected
      {Vec3::Zero(), -0.002, 0.003, 0},         // pulling: no deflection
      {Vec3(0.02, 0.0, 0.0), 1.0, -0.5, 0},     // clamped: x → 5 mm, r → 0
      {Vec3(-0.02, 0.0, 0.0), inf, 0.003, 0}};  // rejected
  deflection.step(contacts, nan);
  deflection.step(contacts, -1.0);
  deflection.update_normals();
  EXPECT_EQ(deflection.rejected_contacts(), 10u);
  for (std::uint32_t v = 0; v < deflection.rest_positions().size(); ++v) {
    ASSERT_TRUE(deflection.mesh().vertices[v].allFinite()) << v;
    ASSERT_TRUE(deflection.mesh().vertex_normals[v].allFinite()) << v;  // after update_normals
    ASSERT_LE(deflection.deflection_m(v), 0.005);
  }
  EXPECT_DOUBLE_EQ(deflection.max_deflection_m(), 0.005);
}

TEST(PointHashGrid, MatchesBruteForceEachPointOnce) {
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> u(-0.1, 0.1);
  std::vector<Vec3> points(3000);
  for (Vec3& p : points) {
    p = Vec3(u(rng), u(rng), 0.2 * u(rng));
  }
  points.push_back(points[5]);  // a duplicate point is still reported (as its own index)
  for (const double cell : {0.003, 0.01, 0.05, 1.0}) {
    const PointHashGrid grid(points, cell);
    for (int q = 0; q < 50; ++q) {
      const Vec3 c(1.5 * u(rng), 1.5 * u(rng), u(rng));
      const double r = std::abs(u(rng)) * (q % 5 == 0 ? 3.0 : 0.3);
      std::vector<std::uint32_t> found;
      grid.for_each_within(c, r, [&](std::uint32_t i, double d2) {
        found.push_back(i);
        EXPECT_DOUBLE_EQ(d2, (points[i] - c).squaredNorm());
      });
      std::vector<std::uint32_t> expected;
      for (std::uint32_t i = 0; i < points.size(); ++i) {
        if ((points[i] - c).squaredNorm() < r * r) {
          expected.push_back(i);
        }
      }
      std::sort(found.begin(), found.end());
      EXPECT_EQ(found, expected) << "cell " << cell << " query " << q;
    }
  }
}

}  // namespace
}  // namespace hapsim
