// Dynamic bodies of any closed mesh in the one world, against analytic answers: a cube dropped on
// a floor rests on its four bottom corners, each a vertex spring carrying a quarter of its weight
// (k·x = m·g / 4, the two materials in series); a cube dropped tilted lands on a face; a small
// cube stacked on a dynamic cube is carried by it and both by the floor; a probe pushing a cube
// along the floor feels the dynamic friction μ·m·g; a cube rests on the Gaussian sheet, which
// carries its weight; the step stays allocation-free and replays to the same bits, after a reset
// too.
#include "hapsim/core/error.h"
#include "hapsim/geometry/mass_properties.h"
#include "hapsim/geometry/procedural.h"
#include "hapsim/world/world.h"

#include "support/allocation_counter.h"
#include "support/body_fixtures.h"

#include <gtest/gtest.h>

#include <cmath>

namespace hapsim {
namespace {

using test::floor_body;
using test::probe_at;

constexpr double kG = 9.81;

MaterialDescription penalty(const char* name, double k, double friction) {
  return test::penalty_material(name, k, 50.0, friction);
}

// A dynamic cube of half side `half_m` (a 12-triangle mesh) whose mass properties come from its
// mesh, as a scene file's would.
BodyDescription cube_body(const char* name, double half_m, double mass_kg, const Iso3& X_world,
                          std::uint32_t material) {
  BodyDescription b;
  b.name = name;
  b.kind = BodyKind::kDynamic;
  b.X_world_body = X_world;
  SegmentDescription s;
  s.name = name;
  s.material = material;
  s.mesh = make_box(Vec3::Constant(half_m));
  const MassProperties mp = mass_properties(s.mesh);
  b.rigid.mass_kg = mass_kg;
  b.rigid.com_body = mp.com;
  b.rigid.inertia_kg_m2 = mp.inertia_per_density * (mass_kg / mp.volume_m3);
  b.segments.push_back(std::move(s));
  return b;
}

Iso3 at(const Vec3& p) {
  return Iso3(Eigen::Translation3d(p));
}

const DeviceInput kAway = probe_at(Vec3(0.0, 0.0, 1.0));

TEST(DynamicMesh, CubeDroppedOnTheFloorRestsOnItsFourCorners) {
  const double half = 0.02;
  const double mass = 0.2;
  WorldDescription d;
  d.materials = {penalty("cube", 20000.0, 0.5), penalty("floor", 20000.0, 0.5)};
  d.bodies = {floor_body(1), cube_body("cube", half, mass, at(Vec3(0.0, 0.0, half + 0.01)), 0)};
  d.tools.push_back(ToolDescription{"probe", 0.005, Vec3::Zero(), -1});
  World world(std::move(d));
  for (int i = 0; i < 2000; ++i) {
    world.step(kAway, 1e-3);
    ASSERT_TRUE(world.body_pose(1).matrix().allFinite());
  }
  // Four corner springs of 10 kN/m (both materials in series) carry m·g.
  const double x = mass * kG / (4.0 * 10000.0);
  const Iso3 X = world.body_pose(1);
  EXPECT_NEAR(X.translation().z(), half - x, 1e-6);
  EXPECT_NEAR(X.translation().x(), 0.0, 1e-9);
  EXPECT_NEAR(X.translation().y(), 0.0, 1e-9);
  EXPECT_LT((X.linear() - Mat3::Identity()).norm(), 1e-6) << "lands flat, does not turn";
  EXPECT_LT(world.state().bodies[1].v_world.norm(), 1e-4);
  ASSERT_EQ(world.last_result().body_contacts.size(), 1U) << "one contact per pair of segments";
  const BodyContact& c = world.last_result().body_contacts.front();
  EXPECT_EQ(c.other_body, BodyIndex{0});
  EXPECT_NEAR(c.force_world_n.z(), mass * kG, 1e-4);
  EXPECT_NEAR(c.normal_world.z(), 1.0, 1e-9);
  EXPECT_NEAR(c.depth_m, x, 1e-6);
}

TEST(DynamicMesh, CubeDroppedTiltedLandsOnAFace) {
  const double half = 0.02;
  const double mass = 0.2;
  Iso3 X0 = at(Vec3(0.01, -0.02, 0.06));
  X0.rotate(Eigen::AngleAxisd(0.5, Vec3(1.0, 0.4, 0.0).normalized()));
  WorldDescription d;
  d.materials = {penalty("cube", 20000.0, 0.6), penalty("floor", 20000.0, 0.6)};
  d.bodies = {floor_body(1), cube_body("cube", half, mass, X0, 0)};
  d.tools.push_back(ToolDescription{"probe", 0.005, Vec3::Zero(), -1});
  World world(std::move(d));
  double highest_speed = 0.0;
  for (int i = 0; i < 4000; ++i) {
    world.step(kAway, 1e-3);
    ASSERT_TRUE(world.body_pose(1).matrix().allFinite());
    highest_speed = std::max(highest_speed, world.state().bodies[1].v_world.norm());
  }
  // Free fall from 6 cm bounds every speed (nothing adds energy).
  EXPECT_LT(highest_speed, std::sqrt(2.0 * kG * 0.06) * 1.05);
  const Iso3 X = world.body_pose(1);
  // One of the cube's axes is vertical: it lies on a face...
  const Vec3 up_body = X.linear().transpose() * Vec3::UnitZ();
  EXPECT_GT(up_body.cwiseAbs().maxCoeff(), std::cos(0.5 * M_PI / 180.0)) << up_body.transpose();
  // ...at the height four corner springs carry it, at rest.
  EXPECT_NEAR(X.translation().z(), half - mass * kG / (4.0 * 10000.0), 1e-5);
  EXPECT_LT(world.state().bodies[1].v_world.norm(), 1e-3);
  EXPECT_LT(world.state().bodies[1].w_world.norm(), 1e-2);
}

TEST(DynamicMesh, SmallCubeStackedOnACubeIsCarriedAndBothByTheFloor) {
  const double big = 0.02;
  const double small = 0.01;
  const double m_big = 0.2;
  const double m_small = 0.05;
  const auto make = [&] {
    WorldDescription d;
    d.materials = {penalty("cube", 20000.0, 0.5), penalty("floor", 20000.0, 0.5)};
    d.bodies = {
        floor_body(1), cube_body("big", big, m_big, at(Vec3(0.0, 0.0, big + 0.002)), 0),
        cube_body("small", small, m_small, at(Vec3(0.003, -0.002, 2.0 * big + small + 0.006)), 0)};
    d.tools.push_back(ToolDescription{"probe", 0.005, Vec3::Zero(), -1});
    return std::make_unique<World>(std::move(d));
  };
  auto world = make();
  for (int i = 0; i < 200; ++i) {
    world->step(kAway, 1e-3);
  }
  const long before = test::allocation_count();
  for (int i = 200; i < 3000; ++i) {
    world->step(kAway, 1e-3);
  }
  EXPECT_EQ(test::allocation_count() - before, 0) << "the step allocates nothing";
  // Floor under the big cube: 4 corners carry both weights; the small cube's 4 bottom corners
  // press into the big cube's top face and carry its own.
  const double k = 10000.0;
  const double z_big = big - (m_big + m_small) * kG / (4.0 * k);
  const double z_small = z_big + big + small - m_small * kG / (4.0 * k);
  EXPECT_NEAR(world->body_pose(1).translation().z(), z_big, 1e-6);
  EXPECT_NEAR(world->body_pose(2).translation().z(), z_small, 1e-6);
  EXPECT_NEAR(world->body_pose(2).translation().x(), 0.003, 1e-4) << "stays where it landed";
  EXPECT_LT(world->state().bodies[2].v_world.norm(), 1e-4);
  ASSERT_EQ(world->last_result().body_contacts.size(), 2U);
  for (const BodyContact& c : world->last_result().body_contacts) {
    const double carried = c.other_body == BodyIndex{0} ? (m_big + m_small) * kG : m_small * kG;
    // The lower-numbered body answers for a pair: the big cube, pushed down by the small one.
    const double sign = c.other_body == BodyIndex{0} ? 1.0 : -1.0;
    EXPECT_NEAR(sign * c.force_world_n.z(), carried, 1e-4) << "contact with " << c.other_body;
  }
  // The same run again gives the same bits.
  auto again = make();
  for (int i = 0; i < 3000; ++i) {
    again->step(kAway, 1e-3);
  }
  EXPECT_EQ(again->body_pose(2).matrix(), world->body_pose(2).matrix());
  EXPECT_EQ(again->body_pose(1).matrix(), world->body_pose(1).matrix());
  // So does the run after a reset (stick points, hints, pass numbers all back to the start).
  world->reset();
  for (int i = 0; i < 3000; ++i) {
    world->step(kAway, 1e-3);
  }
  EXPECT_EQ(again->body_pose(2).matrix(), world->body_pose(2).matrix());
  EXPECT_EQ(again->body_pose(1).matrix(), world->body_pose(1).matrix());
}

// Two light cubes stacked on stiff materials: their contact couples their velocity updates, and
// solved together (not each against the other's old velocity, as stable as explicit Euler: this
// pair shook from 24 kN/m) they settle where the springs carry them at five times that.
TEST(DynamicMesh, LightStiffStackSettlesWhenTouchingBodiesAreSolvedTogether) {
  const double half = 0.01;
  const double mass = 0.025;
  const double k_material = 200000.0;  // both sides: 100 kN/m in series
  WorldDescription d;
  d.materials = {penalty("cube", k_material, 0.5), penalty("floor", k_material, 0.5)};
  d.bodies = {floor_body(1), cube_body("lower", half, mass, at(Vec3(0.0, 0.0, half + 0.001)), 0),
              cube_body("upper", half * 0.8, mass,
                        at(Vec3(0.001, 0.0, 2.0 * half + 0.8 * half + 0.003)), 0)};
  d.tools.push_back(ToolDescription{"probe", 0.005, Vec3::Zero(), -1});
  World world(std::move(d));
  double last_fastest = 0.0;
  for (int i = 0; i < 2000; ++i) {
    world.step(kAway, 1e-3);
    ASSERT_TRUE(world.body_pose(2).matrix().allFinite());
    if (i >= 1500) {
      last_fastest = std::max({last_fastest, world.state().bodies[1].v_world.norm(),
                               world.state().bodies[2].v_world.norm()});
    }
  }
  EXPECT_LT(last_fastest, 1e-4) << "at rest, no shaking";
  const double k = k_material / 2.0;
  const double z_lower = half - 2.0 * mass * kG / (4.0 * k);
  EXPECT_NEAR(world.body_pose(1).translation().z(), z_lower, 1e-6);
  EXPECT_NEAR(world.body_pose(2).translation().z(),
              z_lower + half + 0.8 * half - mass * kG / (4.0 * k), 1e-6);
}

TEST(DynamicMesh, ProbePushingACubeAlongTheFloorFeelsDynamicFriction) {
  const double half = 0.02;
  const double mass = 0.2;
  const double mu = 0.4;
  WorldDescription d;
  d.materials = {penalty("cube", 20000.0, mu), penalty("floor", 20000.0, mu),
                 penalty("probe side", 2000.0, 0.0)};
  d.bodies = {floor_body(1), cube_body("cube", half, mass, at(Vec3(0.0, 0.0, half)), 0)};
  d.tools.push_back(ToolDescription{"probe", 0.005, Vec3::Zero(), -1});
  World world(std::move(d));
  for (int i = 0; i < 300; ++i) {
    world.step(kAway, 1e-3);  // settle
  }
  // The probe comes from −x at the cube's mid-height and pushes at 2 cm/s for 1.5 s.
  const double x0 = -half - 0.005 - 0.002;
  double push_sum_n = 0.0;
  double load_sum_n = 0.0;  // what the probe adds to the weight (its own friction on the face)
  int samples = 0;
  for (int i = 0; i <= 1500; ++i) {
    const double x = x0 + 0.02 * i / 1000.0;
    const StepResult& r = world.step(probe_at(Vec3(x, 0.0, half)), 1e-3);
    if (i > 800) {  // sliding steadily
      push_sum_n -= r.tools[0].force_world_n.x();
      load_sum_n += r.tools[0].force_world_n.z();
      ++samples;
      EXPECT_NEAR(world.state().bodies[1].v_world.x(), 0.02, 1e-4) << "at the probe's speed";
    }
  }
  const double moved = world.body_pose(1).translation().x();
  EXPECT_GT(moved, 0.02);
  EXPECT_LT(moved, 0.03);
  // While it slides at constant speed, the probe holds the cube against the floor's dynamic
  // friction μ·N, N the weight and what the probe's own friction on the face presses down.
  const double normal_n = mass * kG + load_sum_n / samples;
  EXPECT_NEAR(push_sum_n / samples, mu * normal_n, 1e-3 * mu * normal_n);
  // Pushed at mid-height from the side, it slides upright.
  EXPECT_LT((world.body_pose(1).linear() - Mat3::Identity()).norm(), 0.02);
}

// One static segment whose mesh is two walls squeezes a cube between them: the vertex forces on
// its two sides cancel, but friction is limited by what presses on each side (Coulomb: the cube
// hangs when 2·μ·N_side > m·g, falls when not), not by their near-zero sum.
TEST(DynamicMesh, CubeSqueezedInASlotOfOneSegmentHangsByFrictionOnBothSides) {
  const double half = 0.02;
  const double mass = 0.2;
  const double squeeze = 0.0005;  // each wall 0.5 mm into the cube's side
  const auto run = [&](double mu) {
    WorldDescription d;
    d.gravity_m_per_s2 = Vec3(0.0, 0.0, -kG);
    d.materials = {penalty("cube", 20000.0, mu), penalty("wall", 20000.0, mu)};
    BodyDescription slot;
    slot.name = "slot";
    SegmentDescription s;
    s.name = "walls";
    s.material = 1;
    for (const double side : {-1.0, 1.0}) {
      TriangleMesh wall = make_box(Vec3(0.01, 0.05, 0.05));
      const auto first = static_cast<std::uint32_t>(s.mesh.vertices.size());
      for (const Vec3& v : wall.vertices) {
        s.mesh.vertices.push_back(v + Vec3(side * (half + 0.01 - squeeze), 0.0, 0.0));
      }
      for (const auto& t : wall.triangles) {
        s.mesh.triangles.push_back({t[0] + first, t[1] + first, t[2] + first});
      }
    }
    s.mesh.compute_vertex_normals();
    slot.segments.push_back(std::move(s));
    d.bodies = {std::move(slot), cube_body("cube", half, mass, Iso3::Identity(), 0)};
    d.tools.push_back(ToolDescription{"probe", 0.005, Vec3::Zero(), -1});
    World world(std::move(d));
    for (int i = 0; i < 1000; ++i) {
      world.step(kAway, 1e-3);
    }
    return world.body_pose(1).translation().z();
  };
  // Four corner springs of 10 kN/m (in series) on each side: N_side = 4·k·squeeze = 20 N.
  const double n_side = 4.0 * 10000.0 * squeeze;
  const double holds_mu = 0.5;   // 2·μ·N = 20 N > m·g = 1.96 N
  const double slips_mu = 0.02;  // 2·μ·N = 0.8 N < m·g
  ASSERT_GT(2.0 * holds_mu * n_side, mass * kG);
  ASSERT_LT(2.0 * slips_mu * n_side, mass * kG);
  EXPECT_GT(run(holds_mu), -1e-3) << "hangs in the slot (sagging by its stick springs only)";
  EXPECT_LT(run(slips_mu), -0.05) << "slides out of the slot";
}

TEST(DynamicMesh, CubeOnTheSheetIsCarried) {
  const double half = 0.015;
  const double mass = 0.05;
  WorldDescription d;
  d.materials = {penalty("cube", 3000.0, 0.5), penalty("sheet", 3000.0, 0.5)};
  BodyDescription sheet;
  sheet.name = "sheet";
  sheet.kind = BodyKind::kDeformable;
  sheet.deformation = BodyDeformation::kGaussianSheet;
  SegmentDescription s;
  s.name = "sheet";
  s.material = 1;
  s.mesh = make_sheet(sheet.sheet.nodes_per_side, sheet.sheet.side_m);
  s.two_sided = true;
  sheet.segments.push_back(std::move(s));
  d.bodies.push_back(std::move(sheet));
  d.bodies.push_back(cube_body("cube", half, mass, at(Vec3(0.01, 0.0, half + 0.005)), 0));
  d.tools.push_back(ToolDescription{"probe", 0.005, Vec3::Zero(), -1});
  // Its four corners press the sheet together: at 8000 N/m a side (4000 in series, k·c = 0.93
  // for one spring, under the one-spring limit) the corners' dents add up (1.8 times one: the
  // Gaussian profile over the corners' distances) past it, and the world refuses the press.
  WorldDescription too_stiff = d;
  too_stiff.materials = {penalty("cube", 8000.0, 0.5), penalty("sheet", 8000.0, 0.5)};
  EXPECT_THROW(World{too_stiff}, Error);
  World world(std::move(d));
  for (int i = 0; i < 4000; ++i) {
    world.step(kAway, 1e-3);
    ASSERT_TRUE(world.body_pose(1).matrix().allFinite());
  }
  EXPECT_LT(world.state().bodies[1].v_world.norm(), 1e-3);
  ASSERT_EQ(world.last_result().body_contacts.size(), 1U);
  EXPECT_NEAR(world.last_result().body_contacts.front().force_world_n.z(), mass * kG, 1e-3);
  // The sheet sank under it (its elastic field is below rest where the cube sits).
  const Vec3 p = world.body_pose(1).translation();
  EXPECT_LT(world.sheet(0)->height_at(p.x(), p.y(), SheetLayer::kElastic), -1e-4);
  EXPECT_LT(p.z(), half);
}

}  // namespace
}  // namespace hapsim
