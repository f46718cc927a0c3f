// Dynamic bodies and the Gaussian sheet in the one world, against analytic answers: a ball
// dropped on a floor comes to rest where the contact spring carries its weight (k·x = m·g, the
// two materials in series); a ball on the sheet rests with the sheet carrying its weight, dented
// by the Gaussian profile of that weight and by its imprint; two fingertips pinch a ball and lift
// it by friction alone; a probe pressing the sheet feels k·x and the sheet moves under it; the
// step stays allocation-free and replays to the same bits; unusable bodies are refused by name.
#include "hapsim/core/error.h"
#include "hapsim/deform/sheet_profile.h"
#include "hapsim/deform/virtual_sheet.h"
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
using test::sheet_body;

constexpr double kBallRadius = 0.03;
constexpr double kBallMass = 0.1;
constexpr double kG = 9.81;

MaterialDescription penalty(const char* name, double k, double max_force_n, double friction) {
  return test::penalty_material(name, k, max_force_n, friction);
}

BodyDescription ball_body(const Vec3& p_world, std::uint32_t material) {
  BodyDescription b;
  b.name = "ball";
  b.kind = BodyKind::kDynamic;
  b.X_world_body = Iso3(Eigen::Translation3d(p_world));
  SegmentDescription s;
  s.name = "ball";
  s.material = material;
  s.mesh = make_uv_sphere(kBallRadius, 32, 16);
  s.sphere = ExactSphere{Vec3::Zero(), kBallRadius};
  b.segments.push_back(std::move(s));
  b.rigid.mass_kg = kBallMass;
  b.rigid.inertia_kg_m2 = Mat3::Identity() * 0.4 * kBallMass * kBallRadius * kBallRadius;
  return b;
}

// Far from everything: the tools touch nothing.
const DeviceInput kAway = probe_at(Vec3(0.0, 0.0, 1.0));

TEST(DynamicBody, BallDroppedOnTheFloorRestsWhereTheSpringCarriesItsWeight) {
  WorldDescription d;
  d.materials = {penalty("ball", 20000.0, 50.0, 0.5), penalty("floor", 20000.0, 50.0, 0.5)};
  d.bodies = {floor_body(1), ball_body(Vec3(0.0, 0.0, kBallRadius + 0.02), 0)};
  d.tools.push_back(ToolDescription{"probe", 0.005, Vec3::Zero(), -1});
  World world(std::move(d));
  bool touched = false;
  for (int i = 0; i < 3000; ++i) {
    const StepResult& r = world.step(kAway, 1e-3);
    touched = touched || !r.body_contacts.empty();
    ASSERT_TRUE(world.body_pose(1).matrix().allFinite());
  }
  EXPECT_TRUE(touched);
  // Both materials in series: 10 kN/m; at rest k·x = m·g.
  const double x = kBallMass * kG / 10000.0;
  EXPECT_NEAR(world.body_pose(1).translation().z(), kBallRadius - x, 2e-6);
  EXPECT_NEAR(world.body_pose(1).translation().x(), 0.0, 1e-9);
  EXPECT_LT(world.state().bodies[1].v_world.norm(), 1e-4);
  ASSERT_EQ(world.last_result().body_contacts.size(), 1U);
  const BodyContact& c = world.last_result().body_contacts.front();
  EXPECT_EQ(c.other_body, BodyIndex{0});
  EXPECT_NEAR(c.force_world_n.z(), kBallMass * kG, 1e-3);
  EXPECT_NEAR(c.normal_world.z(), 1.0, 1e-9);
}

// Materials in series: an infinitely stiff side gives the other's stiffness, never NaN.
TEST(DynamicBody, ARigidMaterialInSeriesGivesTheOther) {
  ContactMaterial rigid = penalty("rigid", kInf, 50.0, 0.0).contact;
  rigid.damping_n_s_per_m = kInf;
  ContactMaterial soft = penalty("soft", 800.0, 5.0, 0.4).contact;
  soft.damping_n_s_per_m = 3.0;
  const ContactMaterial m = combine_materials(rigid, soft);
  EXPECT_EQ(m.stiffness_n_per_m, 800.0);
  EXPECT_EQ(m.damping_n_s_per_m, 3.0);
  EXPECT_EQ(m.max_force_n, 5.0);
  EXPECT_EQ(m.static_friction, 0.4);
}

TEST(DynamicBody, BallOnTheSheetIsCarriedAndImprintsIt) {
  WorldDescription d;
  d.materials = {penalty("ball", 4000.0, 50.0, 0.5), penalty("sheet", 4000.0, 50.0, 0.5)};
  d.bodies = {sheet_body(1), ball_body(Vec3(0.01, -0.005, kBallRadius + 0.01), 0)};
  d.tools.push_back(ToolDescription{"probe", 0.005, Vec3::Zero(), -1});
  World world(std::move(d));
  double last_second_fastest = 0.0;
  for (int i = 0; i < 4000; ++i) {
    world.step(kAway, 1e-3);
    if (i >= 3000) {
      last_second_fastest = std::max(last_second_fastest, world.state().bodies[1].v_world.norm());
    }
  }
  EXPECT_LT(last_second_fastest, 1e-3) << "at rest, no jitter on the lagging sheet field";
  const VirtualSheet* sheet = world.sheet(0);
  ASSERT_NE(sheet, nullptr);
  ASSERT_EQ(world.last_result().body_contacts.size(), 1U);
  const BodyContact& c = world.last_result().body_contacts.front();
  EXPECT_NEAR(c.force_world_n.z(), kBallMass * kG, 2e-3) << "the sheet carries the ball";
  EXPECT_LT(world.state().bodies[1].v_world.norm(), 1e-3);
  // The sheet's elastic field under the ball is the Gaussian profile of the ball's weight...
  const Vec3 p = world.body_pose(1).translation();
  const double elastic = sheet->height_at(p.x(), p.y(), SheetLayer::kElastic);
  EXPECT_NEAR(-elastic, sheet->profile().depth_m(0.0, kBallMass * kG), 2e-4);
  // ...and the surface shows the ball's lower cap where the cap lies below it (paper 000 Fig. 2).
  const double surface = sheet->height_at(p.x(), p.y(), SheetLayer::kSurface);
  EXPECT_LE(surface, elastic + 1e-12);
  EXPECT_NEAR(surface, std::min(elastic, p.z() - kBallRadius), 2e-3);
  // Surface shown to the viewer is the sheet's.
  EXPECT_EQ(&world.surface(0, 0), &sheet->mesh());
}

TEST(DynamicBody, TwoFingertipsPinchTheBallAndLiftItByFriction) {
  // Two fingertips squeeze the ball at its equator, 1.5 mm into it each side, from the first
  // step; gravity pulls it; the fingers then lift 5 cm in 1 s and hold.
  WorldDescription d;
  d.materials = {penalty("ball", 2000.0, 10.0, 1.0)};
  const Vec3 grip(0.0, 0.0, 0.1);
  d.bodies = {ball_body(grip, 0)};
  const double tip_r = 0.008;
  const double squeeze = 0.0015;
  const double half_gap = kBallRadius + tip_r - squeeze;
  d.tools.push_back(ToolDescription{"thumb", tip_r, Vec3(half_gap, 0.0, 0.0), -1});
  d.tools.push_back(ToolDescription{"index", tip_r, Vec3(-half_gap, 0.0, 0.0), -1});
  World world(std::move(d));
  for (int i = 0; i < 500; ++i) {
    world.step(probe_at(grip), 1e-3);
  }
  // Held where it was, sagging by s: each stick spring stretches s·(1 − r_tip/L) (the tip's
  // contact point turns with the normal, L = R + r_tip − squeeze the centres' distance) and
  // carries k times that; the squeeze N = k·squeeze, now tilted by s/L, pushes down by N·s/L.
  const double k = 2000.0;
  const double L = kBallRadius + tip_r - squeeze;
  const double sag = kBallMass * kG / (2.0 * k * (1.0 - tip_r / L) - 2.0 * k * squeeze / L);
  EXPECT_NEAR(world.body_pose(0).translation().z(), grip.z() - sag, 2e-6);
  for (int i = 0; i <= 1000; ++i) {
    world.step(probe_at(grip + Vec3(0.0, 0.0, 0.05 * i / 1000.0)), 1e-3);
  }
  for (int i = 0; i < 500; ++i) {
    world.step(probe_at(grip + Vec3(0.0, 0.0, 0.05)), 1e-3);
  }
  const Vec3 p = world.body_pose(0).translation();
  EXPECT_NEAR(p.z(), grip.z() + 0.05 - sag, 2e-6) << "lifted with the fingers, no slip";
  EXPECT_NEAR(p.x(), 0.0, 1e-9);
  EXPECT_NEAR(p.y(), 0.0, 1e-9);
  EXPECT_LT(world.state().bodies[0].v_world.norm(), 1e-3);
  // The fingers feel the squeeze and, between them, the weight they carry.
  const Vec3 total =
      world.last_result().tools[0].force_world_n + world.last_result().tools[1].force_world_n;
  EXPECT_NEAR(total.z(), -kBallMass * kG, 1e-3);
  EXPECT_NEAR(world.last_result().tools[0].force_world_n.x(), 2000.0 * squeeze, 0.01);
}

TEST(DynamicBody, ProbePressingTheSheetFeelsTheSpringAndMovesIt) {
  WorldDescription d;
  d.materials = {penalty("sheet", 1000.0, 20.0, 0.0)};
  d.bodies = {sheet_body(0)};
  d.tools.push_back(ToolDescription{"probe", 0.005, Vec3::Zero(), -1});
  d.passivity_damping_factor = 0.0;
  World world(std::move(d));
  const Vec3 p(0.0, 0.0, 0.005 - 0.004);  // 4 mm below the rest surface
  for (int i = 0; i < 400; ++i) {
    world.step(probe_at(p), 1e-3);
  }
  // The sheet gives way under the push (its elastic field lags one step): the probe presses the
  // field, which sinks until k·(4 mm − sink) = F and sink = profile(F).
  const VirtualSheet& sheet = *world.sheet(0);
  const double f = world.last_result().tools[0].force_world_n.z();
  const double sink = -sheet.height_at(0.0, 0.0, SheetLayer::kElastic);
  EXPECT_GT(f, 0.5);
  EXPECT_NEAR(f, 1000.0 * (0.004 - sink), 1e-3);
  // The sink is the sheet's own answer to that force (the Gaussian on its grid, interpolated).
  VirtualSheet reference;
  const SheetContact push{Vec3::Zero(), f};
  reference.apply_contacts({&push, 1});
  EXPECT_NEAR(sink, -reference.height_at(0.0, 0.0, SheetLayer::kElastic), 1e-6);
}

// A live material edit that would make a press on the sheet overshoot every step (a contact
// spring stiffer than the sheet gives way under a push, k·compliance ≥ 1) is refused as the loader
// refuses it; a softer one is taken.
TEST(DynamicBody, LiveMaterialEditsThatAPressOnTheSheetCannotSettleAreRefused) {
  WorldDescription d;
  d.materials = {penalty("ball", 4000.0, 50.0, 0.5), penalty("sheet", 4000.0, 50.0, 0.5)};
  d.bodies = {sheet_body(1), ball_body(Vec3(0.0, 0.0, 0.1), 0)};
  const double compliance_m_per_n =
      GaussianSheetProfile(d.bodies[0].sheet_profile).depth_m(0.0, 1.0);
  d.tools.push_back(ToolDescription{"probe", 0.005, Vec3::Zero(), -1});
  const double limit_n_per_m = 1.0 / compliance_m_per_n;
  // A device rated at half the limit: the tool's press is clamped to it, the ball's is not.
  WorldOptions options;
  options.max_stiffness_n_per_m = 0.5 * limit_n_per_m;
  World world(std::move(d), options);
  ContactMaterial stiff = world.material_contact(1);
  stiff.stiffness_n_per_m = 1e9;
  ContactMaterial stiff_ball = world.material_contact(0);
  stiff_ball.stiffness_n_per_m = 1e9;
  EXPECT_TRUE(world.set_material_contact(1, stiff)) << "the tool's press is clamped; 4 kN/m ball";
  EXPECT_FALSE(world.set_material_contact(0, stiff_ball)) << "ball and sheet in series: 0.5 GN/m";
  EXPECT_EQ(world.material_contact(0).stiffness_n_per_m, 4000.0) << "nothing changed";
  stiff_ball.stiffness_n_per_m = 0.9 * limit_n_per_m;  // in series with the stiff sheet: 0.9 L
  EXPECT_TRUE(world.set_material_contact(0, stiff_ball));
  // Without the clamp the tool's own press decides.
  World unclamped(world.description());
  EXPECT_FALSE(unclamped.set_material_contact(1, stiff));
  stiff.stiffness_n_per_m = 0.9 * limit_n_per_m;
  EXPECT_TRUE(unclamped.set_material_contact(1, stiff));
}

TEST(DynamicBody, StepAllocatesNothingAndReplaysBitForBit) {
  const auto make = [] {
    WorldDescription d;
    d.materials = {penalty("ball", 4000.0, 50.0, 0.5), penalty("sheet", 4000.0, 50.0, 0.5),
                   penalty("floor", 20000.0, 50.0, 0.5)};
    d.bodies = {sheet_body(1), floor_body(2), ball_body(Vec3(0.05, 0.0, 0.1), 0)};
    d.bodies[1].X_world_body = Iso3(Eigen::Translation3d(0.0, 0.0, -0.2));
    d.tools.push_back(ToolDescription{"probe", 0.005, Vec3::Zero(), -1});
    return std::make_unique<World>(std::move(d));
  };
  auto a = make();
  auto b = make();
  const auto input = [](int i) { return probe_at(Vec3(0.05, 0.0, 0.2 - 1e-4 * i)); };
  for (int i = 0; i < 100; ++i) {
    a->step(input(i), 1e-3);
  }
  const long before = test::allocation_count();
  for (int i = 100; i < 2000; ++i) {
    a->step(input(i), 1e-3);
  }
  EXPECT_EQ(test::allocation_count() - before, 0);
  for (int i = 0; i < 2000; ++i) {
    b->step(input(i), 1e-3);
  }
  EXPECT_EQ(a->body_pose(2).matrix(), b->body_pose(2).matrix());
  EXPECT_EQ(a->last_result().tools[0].force_world_n, b->last_result().tools[0].force_world_n);
}

TEST(DynamicBody, UnusableBodiesAreRefusedByName) {
  WorldDescription d;
  d.materials = {penalty("ball", 4000.0, 50.0, 0.5)};
  d.bodies = {ball_body(Vec3::Zero(), 0)};
  d.bodies[0].rigid.mass_kg = 0.0;
  EXPECT_THROW(
      {
        try {
          World w(d);
        } catch (const Error& e) {
          EXPECT_NE(std::string(e.what()).find("body 'ball'"), std::string::npos) << e.what();
          throw;
        }
      },
      Error);
  d.bodies[0].rigid.mass_kg = 0.1;
  d.bodies[0].rigid.inertia_kg_m2(0, 0) = -1.0;
  EXPECT_THROW(World w(d), Error);
  d.bodies[0].rigid.inertia_kg_m2 = Mat3::Identity() * 1e-4;
  d.materials[0].response = ContactResponse::kProxy;
  EXPECT_THROW(World w(d), Error);
}

}  // namespace
}  // namespace hapsim
