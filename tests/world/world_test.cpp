// World::step against analytic answers: flat faces give exact depths, so the penalty force must be
// k·x exactly; a fast probe must never pass a 1 mm plate or an open sheet; forces stay within
// every limit and finite; deformation follows eq. 1 and recovers; the step allocates nothing and
// replays to the same bits.
#include "hapsim/world/world.h"
#include "hapsim/collision/mesh_bvh.h"
#include "hapsim/core/error.h"
#include "hapsim/deform/vertex_deflection.h"
#include "hapsim/geometry/procedural.h"
#include "hapsim/kinematics/hand_model.h"

#include "support/allocation_counter.h"

#include <gtest/gtest.h>

#include <atomic>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <limits>
#include <new>

namespace hapsim {
namespace {

MaterialDescription material(const char* name, ContactResponse response, double k,
                             double max_penetration_m, double max_force_n) {
  MaterialDescription m;
  m.name = name;
  m.response = response;
  m.contact.stiffness_n_per_m = k;
  m.contact.max_penetration_m = max_penetration_m;
  m.contact.max_force_n = max_force_n;
  return m;
}

// A box body whose top face is the plane z = 0 (box centred at z = -half_z).
WorldDescription box_world(ContactResponse response, double half_z, BodyKind kind,
                           double tool_radius_m) {
  WorldDescription w;
  w.name = "box";
  w.materials.push_back(material("tissue", response, 500.0, 0.01, 4.0));
  w.passivity_damping_factor = 0.0;  // the analytic checks below are static (no velocity)
  BodyDescription body;
  body.name = "block";
  body.kind = kind;
  body.X_world_body = Iso3(Eigen::Translation3d(0, 0, -half_z));
  SegmentDescription seg;
  seg.name = "block";
  seg.mesh = make_box(Vec3(0.05, 0.05, half_z));
  body.segments.push_back(std::move(seg));
  w.bodies.push_back(std::move(body));
  ToolDescription tool;
  tool.name = "tip";
  tool.radius_m = tool_radius_m;
  w.tools.push_back(tool);
  return w;
}

DeviceInput at(const Vec3& p, double t = 0.0) {
  DeviceInput in;
  in.time_s = t;
  in.p_world = p;
  return in;
}

TEST(World, PenaltyForceIsHookeOnAFlatFace) {
  World world(box_world(ContactResponse::kPenalty, 0.02, BodyKind::kStatic, 0.0));
  world.step(at(Vec3(0.001, 0.002, 0.01)), 1e-3);  // above: free
  EXPECT_EQ(world.last_result().tools[0].force_world_n, Vec3::Zero());
  for (double depth : {0.001, 0.004, 0.0075}) {
    World w(box_world(ContactResponse::kPenalty, 0.02, BodyKind::kStatic, 0.0));
    const StepResult& r = w.step(at(Vec3(0.001, 0.002, -depth)), 1e-3);
    EXPECT_NEAR(r.tools[0].force_world_n.z(), 500.0 * depth, 1e-9) << depth;
    EXPECT_NEAR(r.tools[0].force_world_n.head<2>().norm(), 0.0, 1e-12);
    ASSERT_EQ(r.contacts.size(), 1u);
    EXPECT_NEAR(r.contacts[0].depth_m, depth, 1e-12);
    EXPECT_FALSE(r.contacts[0].proxy);
  }
}

TEST(World, SphereToolDepthIncludesItsRadius) {
  World world(box_world(ContactResponse::kPenalty, 0.02, BodyKind::kStatic, 0.005));
  const StepResult& r = world.step(at(Vec3(0, 0, 0.003)), 1e-3);  // 2 mm into the face
  EXPECT_NEAR(r.tools[0].force_world_n.z(), 500.0 * 0.002, 1e-9);
}

TEST(World, PenaltyForceSaturatesAtTheSegmentLimits) {
  // max penetration 10 mm → at most 5 N by the spring, capped at 4 N by the segment.
  for (double depth : {0.009, 0.012, 0.03}) {  // 0.03: deeper than the reach, inside the box
    World world(box_world(ContactResponse::kPenalty, 0.02, BodyKind::kStatic, 0.0));
    const StepResult& r = world.step(at(Vec3(0, 0, -depth)), 1e-3);
    EXPECT_NEAR(r.tools[0].force_world_n.norm(), 4.0, 1e-9) << depth;
  }
}

TEST(World, ProxyForceOnAFlatFaceAndSliding) {
  World world(box_world(ContactResponse::kProxy, 0.02, BodyKind::kStatic, 0.0));
  world.step(at(Vec3(0, 0, 0.002)), 1e-3);
  // Press 3 mm in, in small steps so the proxy settles, then hold.
  for (int i = 1; i <= 30; ++i) {
    world.step(at(Vec3(0, 0, 0.002 - 0.005 * i / 30.0)), 1e-3);
  }
  const StepResult& r = world.step(at(Vec3(0, 0, -0.003)), 1e-3);
  EXPECT_NEAR(r.tools[0].proxy_world.z(), 0.0, 2e-5);
  EXPECT_NEAR(r.tools[0].force_world_n.z(), 500.0 * 0.003, 500.0 * 2e-5);
  ASSERT_GE(r.contacts.size(), 1u);
  EXPECT_TRUE(r.contacts[0].proxy);
}

// The tool crosses a plate at 1 m/s (1 mm per 1 kHz step): the proxy must stay above it at
// every step and the force must push up, for a 1 mm plate and for an open two-sided sheet.
void expect_no_pop_through(WorldDescription w, double top_z) {
  World world(std::move(w));
  for (int i = 0; i <= 60; ++i) {
    const double z = 0.02 - 0.001 * i;  // from 20 mm above to 40 mm below the plate
    const StepResult& r = world.step(at(Vec3(0.003, -0.002, z)), 1e-3);
    ASSERT_GE(r.tools[0].proxy_world.z(), top_z - 1e-6) << "step " << i << " z " << z;
    if (z < top_z - 0.001) {
      EXPECT_GT(r.tools[0].force_world_n.z(), 0.0) << "step " << i;
    }
    EXPECT_LE(r.tools[0].force_world_n.norm(), 4.0 + 1e-9);
  }
}

TEST(World, NoPopThroughAThinPlateAtOneMetrePerSecond) {
  expect_no_pop_through(box_world(ContactResponse::kProxy, 0.0005, BodyKind::kStatic, 0.0), 0.0);
  expect_no_pop_through(box_world(ContactResponse::kProxy, 0.0005, BodyKind::kStatic, 0.004), 0.0);
}

TEST(World, NoPopThroughAnOpenSheetAtOneMetrePerSecond) {
  WorldDescription w = box_world(ContactResponse::kProxy, 0.0005, BodyKind::kStatic, 0.0);
  w.bodies[0].X_world_body = Iso3::Identity();
  w.bodies[0].segments[0].mesh = make_sheet(16, 0.2);  // z = 0, open
  w.bodies[0].segments[0].two_sided = true;
  expect_no_pop_through(std::move(w), 0.0);
}

// A probe driven down through a 2 mm penalty plate (0.1 mm per step): past the middle the nearest
// surface is the bottom face, whose outward normal points down; the force must still never point
// further in (down), and leaving through the bottom is one pop-through, reported by the step.
TEST(World, PenaltyPlateNeverPullsTheToolThroughAndCountsThePopThrough) {
  WorldDescription w = box_world(ContactResponse::kPenalty, 0.001, BodyKind::kStatic, 0.0);
  w.materials[0].contact.max_penetration_m = 0.05;  // soft and deep: the probe can go through
  w.materials[0].contact.max_force_n = 100.0;
  World world(std::move(w));
  int pop_throughs = 0;
  double deepest_force_z = 0.0;
  for (int i = 0; i <= 60; ++i) {
    const double z = 0.001 - 0.0001 * i;  // from 1 mm above to 5 mm below the 2 mm plate
    const StepResult& r = world.step(at(Vec3(0.003, -0.002, z)), 1e-3);
    const Vec3& f = r.tools[0].force_world_n;
    EXPECT_GE(f.z(), 0.0) << "pulled in at z " << z;
    EXPECT_NEAR(f.head<2>().norm(), 0.0, 1e-9);
    if (z < 0.0 && z > -0.002) {
      // Depth below the top face the probe entered through, even past the middle.
      EXPECT_NEAR(f.z(), 500.0 * -z, 1e-9) << "z " << z;
      deepest_force_z = std::max(deepest_force_z, f.z());
    }
    pop_throughs += r.penalty_pop_throughs;
  }
  EXPECT_GT(deepest_force_z, 0.9);
  EXPECT_EQ(pop_throughs, 1);
}

// After a pause (World::forget_tool_motion) the tool may come back anywhere: a side crossed before
// the pause is forgotten. Half way through a 2 mm plate from above, paused, back 0.2 mm inside the
// bottom face: the plate pushes it out of the bottom (k·0.2 mm down), not up along the old side.
TEST(World, APauseForgetsWhichSideOfAPenaltyPlateTheToolCameFrom) {
  WorldDescription w = box_world(ContactResponse::kPenalty, 0.001, BodyKind::kStatic, 0.0);
  w.materials[0].contact.max_penetration_m = 0.05;
  w.materials[0].contact.max_force_n = 100.0;
  World world(std::move(w));
  for (int i = 0; i <= 15; ++i) {
    world.step(at(Vec3(0.003, -0.002, 0.001 - 0.0001 * i)), 1e-3);  // down to 0.5 mm past middle
  }
  EXPECT_GT(world.last_result().tools[0].force_world_n.z(), 0.0) << "pushed back up: crossed";
  world.forget_tool_motion();
  const StepResult& r = world.step(at(Vec3(0.003, -0.002, -0.0018)), 1e-3);
  EXPECT_NEAR(r.tools[0].force_world_n.z(), -500.0 * 0.0002, 1e-9);
  EXPECT_EQ(r.penalty_pop_throughs, 0);
}

// When the device's source changes (a device host takes over from the scene's script, or lets
// go) the tool lands anywhere: its proxy starts afresh where the device now is. Dragged there
// from the old contact instead, a proxy left on the block's top face with the device 1 m away
// and below that face's plane slid along the face for tens of cycles, rendering the block's
// force limit at a device nowhere near it (serve answered a host 1 m above the knee with 6 N).
// A pause keeps the proxy: a device back inside the block still feels its face.
TEST(World, RestartedToolsLandWhereTheDeviceIsAndFeelNothingFromWhereTheyWere) {
  WorldDescription w = box_world(ContactResponse::kProxy, 0.02, BodyKind::kStatic, 0.0);
  w.materials[0].contact.static_friction = 0.3;
  w.materials[0].contact.dynamic_friction = 0.2;
  World world(std::move(w));
  const auto press = [&] {
    for (int i = 0; i <= 30; ++i) {
      world.step(at(Vec3(0.0, 0.0, 0.002 - 0.005 * i / 30.0)), 1e-3);  // to 3 mm in
    }
    ASSERT_GT(world.last_result().command.force_world_n.z(), 1.0);
  };
  press();
  const Vec3 far_away(1.0, 0.0, -0.5);  // outside the block, below its top face's plane
  world.restart_tools();
  for (int i = 0; i < 3; ++i) {
    const StepResult& r = world.step(at(far_away), 1e-3);
    EXPECT_EQ(r.command.force_world_n, Vec3::Zero()) << "cycle " << i;
    EXPECT_TRUE(r.contacts.empty()) << "cycle " << i;
    EXPECT_TRUE(r.tools[0].proxy_world.isApprox(far_away, 1e-12)) << "cycle " << i;
    EXPECT_EQ(r.penalty_pop_throughs, 0);
  }
  world.restart_tools();
  press();
  world.forget_tool_motion();  // a pause: the proxy stays on the face
  const StepResult& r = world.step(at(Vec3(0.0, 0.0, -0.002)), 1e-3);
  EXPECT_NEAR(r.command.force_world_n.z(), 500.0 * 0.002, 500.0 * 2e-5);
}

// A glove reading with a non-finite finger angle is unusable: the fingertips are held where they
// were and nothing is pushed (never a NaN position or force).
TEST(World, AGloveAngleThatIsNotFiniteHoldsTheHand) {
  WorldDescription w = box_world(ContactResponse::kPenalty, 0.02, BodyKind::kStatic, 0.008);
  w.has_hand = true;
  w.tools[0].finger = 1;
  World world(std::move(w));
  DeviceInput in = at(Vec3(-0.05, 0.0, 0.02));
  in.joint_count = kHandFingers * kGloveAnglesPerFinger;
  in.joint_rad[4] = 0.8;
  const Vec3 before = world.step(in, 1e-3).tools[0].p_world;
  ASSERT_TRUE(before.allFinite());
  in.joint_rad[4] = std::numeric_limits<double>::quiet_NaN();
  in.p_world.z() -= 0.01;
  const StepResult& r = world.step(in, 1e-3);
  EXPECT_EQ(r.tools[0].p_world, before);
  EXPECT_EQ(r.tools[0].force_world_n, Vec3::Zero());
  EXPECT_EQ(r.command.finger_force_n[1], 0.0);
  EXPECT_EQ(r.command.force_world_n, Vec3::Zero());
}

// Sliding over a curved penalty body turns the normal gradually: no crossing, no pop-through, the
// force radial all the way round, when the probe circles a sphere half way at a constant depth.
TEST(World, SlidingRoundAPenaltySphereIsNotAPopThrough) {
  WorldDescription w = box_world(ContactResponse::kPenalty, 0.02, BodyKind::kStatic, 0.0);
  w.bodies[0].X_world_body = Iso3::Identity();
  w.bodies[0].segments[0].mesh = make_uv_sphere(0.03, 128, 64);
  World world(std::move(w));
  int pop_throughs = 0;
  for (int i = 0; i <= 400; ++i) {
    const double a = M_PI * i / 400.0;
    const Vec3 p = 0.028 * Vec3(std::cos(a), std::sin(a), 0.0);  // 2 mm deep
    const StepResult& r = world.step(at(p), 1e-3);
    const Vec3& f = r.tools[0].force_world_n;
    ASSERT_GT(f.norm(), 0.5) << "step " << i;
    EXPECT_GT(f.normalized().dot(p.normalized()), 0.99) << "step " << i;
    pop_throughs += r.penalty_pop_throughs;
  }
  world.step(at(Vec3(-0.05, 0.0, 0.0)), 1e-3);  // out through the side it came from
  EXPECT_EQ(pop_throughs + world.last_result().penalty_pop_throughs, 0);
}

// Two fingertips on one deformable penalty block (top face z = 0, k = 500 N/m, eq. 1's d0 =
// x·elasticity for point tools): the second sits 4 mm beside the first and `second_dz_m` above it
// (negative: deeper).
WorldDescription two_finger_block(double second_dz_m, double elasticity) {
  WorldDescription w = box_world(ContactResponse::kPenalty, 0.02, BodyKind::kDeformable, 0.0);
  w.materials[0].contact.max_penetration_m = 0.02;
  w.materials[0].contact.max_force_n = 20.0;
  w.materials[0].deflection.elasticity_factor = elasticity;
  w.materials[0].deflection.recovery_time_constant_s = 0.05;
  w.tools[0].finger = 0;
  ToolDescription second = w.tools[0];
  second.name = "second";
  second.finger = 1;
  second.offset_device = Vec3(0.004, 0.0, second_dz_m);
  w.tools.push_back(second);
  return w;
}

// Eq. 1 (point tools): the dent a press of depth x leaves 4 mm away.
double dent_4mm_away(double x, double elasticity) {
  return VertexDeflection::deflection_profile_m(0.004, x, elasticity * x);
}

// Deformation changes what a later contact feels: each fingertip feels the surface as the other
// one's dent left it, not the rest surface — F = k·(own depth − the other's eq. 1 dent there).
TEST(World, EachFingertipFeelsTheOthersDent) {
  World world(two_finger_block(-0.001, 2.5));  // the second 1 mm deeper
  for (int i = 0; i < 50; ++i) {
    world.step(at(Vec3(0.0, 0.0, -0.003)), 1e-3);  // first 3 mm in, second 4 mm
  }
  const StepResult& r = world.last_result();
  EXPECT_NEAR(r.command.finger_force_n[0], 500.0 * (0.003 - dent_4mm_away(0.004, 2.5)), 1e-9);
  EXPECT_NEAR(r.command.finger_force_n[1], 500.0 * (0.004 - dent_4mm_away(0.003, 2.5)), 1e-9);
  EXPECT_LT(r.command.finger_force_n[1], 500.0 * 0.004 * 0.7);  // well below the rest surface's
}

// Two users in one world (a trainee's fingertip on device 0, an instructor's probe on device 1,
// World::set_device_input): each tool is placed by its own device, each feels the other's dent
// as two fingertips of one hand do, and the step's command holds device 0's force alone (the
// instructor's reaches the instructor through its tool's result: a device host renders it).
TEST(World, TwoUsersEachPlaceTheirOwnToolAndFeelTheOthersDent) {
  WorldDescription w = two_finger_block(0.0, 2.5);
  w.tools[0].finger = -1;
  w.tools[1].finger = -1;
  w.tools[1].offset_device = Vec3::Zero();
  w.tools[1].device = 1;
  w.device_hosts = {"trainee", "instructor"};
  World world(std::move(w));
  // Until the instructor's device is heard from, its tool holds with no force.
  const StepResult& alone = world.step(at(Vec3(0.0, 0.0, -0.003)), 1e-3);
  EXPECT_EQ(alone.tools[1].force_world_n, Vec3::Zero());
  EXPECT_NEAR(alone.command.force_world_n.z(), 500.0 * 0.003, 1e-9);
  for (int i = 0; i < 50; ++i) {
    world.set_device_input(1, at(Vec3(0.004, 0.0, -0.004)));  // 4 mm beside, 4 mm in
    world.step(at(Vec3(0.0, 0.0, -0.003)), 1e-3);
  }
  const StepResult& r = world.last_result();
  EXPECT_EQ(r.tools[1].p_world, Vec3(0.004, 0.0, -0.004));
  EXPECT_NEAR(r.tools[0].force_world_n.z(), 500.0 * (0.003 - dent_4mm_away(0.004, 2.5)), 1e-9);
  EXPECT_NEAR(r.tools[1].force_world_n.z(), 500.0 * (0.004 - dent_4mm_away(0.003, 2.5)), 1e-9);
  EXPECT_EQ(r.command.force_world_n, r.tools[0].force_world_n);  // the trainee's alone
  // The instructor lets go (an unhealthy input): that tool holds with no force, the trainee's
  // press goes on and no longer feels the instructor's dent once it has recovered.
  DeviceInput gone = at(Vec3(0.004, 0.0, -0.004));
  gone.healthy = false;
  world.set_device_input(1, gone);
  for (int i = 0; i < 1000; ++i) {
    world.step(at(Vec3(0.0, 0.0, -0.003)), 1e-3);
  }
  EXPECT_EQ(world.last_result().tools[1].force_world_n, Vec3::Zero());
  EXPECT_NEAR(world.last_result().tools[0].force_world_n.z(), 500.0 * 0.003, 1e-6);
}

// A fingertip inside the rest surface but clear of the other's dent feels nothing.
TEST(World, AFingertipHoveringInADentFeelsNothing) {
  World world(two_finger_block(0.0025, 2.5));  // the second 2.5 mm higher
  // Down from 1 mm above to 5 mm in (0.1 mm a step), then hold: the second, 2.5 mm higher,
  // stays inside the first's dent all the way (at 3, 4 and 5 mm: 1.3, 2.6 and 3.8 mm deep there).
  for (int i = 0; i <= 260; ++i) {
    const double depth = std::min(0.005, -0.001 + 1e-4 * i);
    world.step(at(Vec3(0.0, 0.0, -depth)), 1e-3);
  }
  ASSERT_GT(dent_4mm_away(0.005, 2.5), 0.0025);  // the dent there is deeper than the second
  const StepResult& r = world.last_result();
  EXPECT_EQ(r.command.finger_force_n[1], 0.0);
  EXPECT_EQ(r.tools[1].contact_count, 0);
  EXPECT_NEAR(r.command.finger_force_n[0], 500.0 * 0.005, 1e-9);
}

// As a dent forms and recovers the other fingertip's force changes smoothly: no step above one
// just-noticeable difference (7 %) per millisecond, over a press, a hold and a release.
TEST(World, ForceStaysContinuousAsDentsFormAndRecover) {
  World world(two_finger_block(-0.001, 1.5));
  std::array<double, 2> last{0.0, 0.0};
  double steepest = 0.0;
  for (int k = 0; k < 600; ++k) {
    const double t = 1e-3 * k;
    // Down 6 mm over 150 ms, hold 150 ms, back up over 300 ms.
    const double depth = t < 0.15 ? 0.04 * t - 0.001 : t < 0.3 ? 0.005 : 0.005 - 0.02 * (t - 0.3);
    const StepResult& r = world.step(at(Vec3(0.0, 0.0, -depth)), 1e-3);
    for (std::size_t f = 0; f < 2; ++f) {
      const double now = r.command.finger_force_n[f];
      const double larger = std::max(now, last[f]);
      if (larger > 0.5) {  // a press at 40 mm/s adds 0.02 N a step: 4 % of 0.5 N
        steepest = std::max(steepest, std::abs(now - last[f]) / larger);
      }
      last[f] = now;
    }
  }
  EXPECT_LT(steepest, 0.07);
}

// A press that comes back to a dent still recovering feels the dented surface: less force at
// first, rising smoothly to the rest surface's k·x as the tissue recovers under the finger.
TEST(World, AReturningPressFeelsTheRecoveringDent) {
  WorldDescription w = box_world(ContactResponse::kPenalty, 0.02, BodyKind::kDeformable, 0.0);
  w.bodies[0].X_world_body = Iso3::Identity();
  w.bodies[0].segments[0].mesh = make_uv_sphere(0.05, 256, 128);  // ~1.2 mm vertex spacing
  w.materials[0].contact.max_penetration_m = 0.02;
  w.materials[0].deflection.recovery_time_constant_s = 0.05;
  World world(std::move(w));
  const auto depth_at = [](double d) { return at(Vec3(0.05 - d, 0.0, 0.0)); };
  for (int i = 0; i < 100; ++i) {
    world.step(depth_at(std::min(0.005, 1e-4 * i)), 1e-3);  // press 5 mm and hold
  }
  world.step(at(Vec3(0.08, 0.0, 0.0)), 1e-3);  // off for 3 ms: the dent starts recovering
  world.step(at(Vec3(0.08, 0.0, 0.0)), 1e-3);
  world.step(at(Vec3(0.08, 0.0, 0.0)), 1e-3);
  double force = world.step(depth_at(0.003), 1e-3).tools[0].force_world_n.norm();
  EXPECT_LT(force, 0.5 * 500.0 * 0.003) << "the dent (about 4.7 mm deep) is still there";
  double previous = force;
  double steepest = 0.0;
  for (int i = 0; i < 500; ++i) {
    force = world.step(depth_at(0.003), 1e-3).tools[0].force_world_n.norm();
    EXPECT_GE(force, previous - 1e-12);  // the tissue comes back, never gives way
    if (force > 0.5) {
      steepest = std::max(steepest, (force - previous) / force);
    }
    previous = force;
  }
  EXPECT_NEAR(force, 500.0 * 0.003, 1e-3);  // recovered: the rest surface's spring again
  EXPECT_LT(steepest, 0.07);
}

TEST(World, NaNAndUnhealthyInputGiveZeroForce) {
  World world(box_world(ContactResponse::kProxy, 0.02, BodyKind::kDeformable, 0.0));
  world.step(at(Vec3(0, 0, 0.001)), 1e-3);
  world.step(at(Vec3(0, 0, -0.002)), 1e-3);
  EXPECT_GT(world.last_result().tools[0].force_world_n.norm(), 0.0);
  const double nan = std::numeric_limits<double>::quiet_NaN();
  const StepResult& r = world.step(at(Vec3(nan, 0, 0)), 1e-3);
  EXPECT_EQ(r.tools[0].force_world_n, Vec3::Zero());
  EXPECT_EQ(r.command.force_world_n, Vec3::Zero());
  DeviceInput sick = at(Vec3(0, 0, -0.002));
  sick.healthy = false;
  EXPECT_EQ(world.step(sick, 1e-3).command.force_world_n, Vec3::Zero());
  DeviceInput bad_q = at(Vec3(0, 0, -0.002));
  bad_q.q_world = Quat(0, 0, 0, 0);
  EXPECT_EQ(world.step(bad_q, 1e-3).command.force_world_n, Vec3::Zero());
  EXPECT_TRUE(world.step(at(Vec3(0, 0, -0.002)), nan).command.force_world_n.allFinite());
}

// A deformable open sheet at z = 0 with a node at the origin (65 nodes over 10 cm).
WorldDescription sheet_world(double tool_radius_m) {
  WorldDescription w =
      box_world(ContactResponse::kProxy, 0.02, BodyKind::kDeformable, tool_radius_m);
  w.bodies[0].segments[0].mesh = make_sheet(65, 0.1);
  w.bodies[0].segments[0].two_sided = true;
  w.bodies[0].X_world_body = Iso3::Identity();
  w.materials[0].deflection.recovery_time_constant_s = 0.02;
  return w;
}

TEST(World, DeformationFollowsThePressAndRecovers) {
  World world(sheet_world(0.0));
  world.step(at(Vec3(0, 0, 0.002)), 1e-3);
  for (int i = 1; i <= 40; ++i) {
    world.step(at(Vec3(0, 0, 0.002 - 0.006 * i / 40.0)), 1e-3);
  }
  // Pressed 4 mm: the deepest vertex moved by about the depth (eq. 1: δ(0) = x).
  EXPECT_NEAR(world.current_deflection_m(0, 0), 0.004, 2e-5);
  // The deformed surface's exact query (refitted) equals one built from scratch on it.
  const ProximityQuery& refitted = world.deformed_query(0, 0);
  const MeshBvh fresh(world.surface(0, 0));
  for (const Vec3& p : {Vec3(0, 0, 0.001), Vec3(0.003, 0.001, -0.002), Vec3(-0.01, 0.004, 0.0)}) {
    const SurfacePoint a = refitted.closest_point(p);
    const SurfacePoint b = fresh.closest_point(p);
    EXPECT_NEAR(std::abs(a.signed_distance), std::abs(b.signed_distance), 1e-12);
    EXPECT_NEAR((a.point - b.point).norm(), 0.0, 1e-12);
  }
  // Release: it recovers to rest.
  for (int i = 0; i < 1000; ++i) {
    world.step(at(Vec3(0, 0, 0.02)), 1e-3);
  }
  EXPECT_EQ(world.current_deflection_m(0, 0), 0.0);
}

TEST(World, DampingNeverBelowThePassivityFloor) {
  WorldDescription w = box_world(ContactResponse::kProxy, 0.02, BodyKind::kStatic, 0.0);
  w.passivity_damping_factor = 1.0;
  w.materials[0].contact.damping_n_s_per_m = 0.1;
  World world(std::move(w), WorldOptions{.max_stiffness_n_per_m = 400.0});
  const ContactMaterial m = world.effective_material(0, 1e-3);
  EXPECT_EQ(m.stiffness_n_per_m, 400.0);         // clamped to the device
  EXPECT_NEAR(m.damping_n_s_per_m, 0.4, 1e-15);  // k·T, above the material's 0.1
  EXPECT_EQ(world.effective_material(0, 1e-5).damping_n_s_per_m, 0.1);  // material's own wins
}

// A rigid material (the rig's ball, kRigidStiffness_n_per_m) pressed by a tool: the device's
// stiffest spring, damped by the passivity floor, not by the 1e12 N*s/m meant for body pairs; a
// press moving 0.1 m/s into it stays a few newtons.
TEST(World, ARigidMaterialUnderAToolIsTheDevicesStiffestSpring) {
  WorldDescription w = box_world(ContactResponse::kPenalty, 0.02, BodyKind::kStatic, 0.0);
  w.materials[0].contact.stiffness_n_per_m = kRigidStiffness_n_per_m;
  w.materials[0].contact.damping_n_s_per_m = kRigidDamping_n_s_per_m;
  w.materials[0].contact.max_force_n = 1e4;
  w.passivity_damping_factor = 1.0;
  World world(std::move(w), WorldOptions{.max_stiffness_n_per_m = 400.0});
  const ContactMaterial m = world.effective_material(0, 1e-3);
  EXPECT_EQ(m.stiffness_n_per_m, 400.0);
  EXPECT_NEAR(m.damping_n_s_per_m, 0.4, 1e-15);  // the floor k·T
  world.step(at(Vec3(0, 0, -0.0019)), 1e-3);
  const StepResult& r = world.step(at(Vec3(0, 0, -0.002)), 1e-3);
  EXPECT_TRUE(r.command.force_world_n.allFinite());
  EXPECT_GT(r.command.force_world_n.z(), 0.5);
  EXPECT_LT(r.command.force_world_n.z(), 2.0);
}

TEST(World, FingerToolsDriveFingerChannels) {
  WorldDescription w = box_world(ContactResponse::kPenalty, 0.02, BodyKind::kStatic, 0.0);
  w.tools[0].finger = 1;
  ToolDescription second = w.tools[0];
  second.name = "other";
  second.finger = -1;
  second.offset_device = Vec3(0.0, 0.0, 0.01);  // 1 cm higher: free while the first presses
  w.tools.push_back(second);
  World world(std::move(w));
  const StepResult& r = world.step(at(Vec3(0, 0, -0.002)), 1e-3);
  EXPECT_EQ(r.command.finger_count, 2);
  EXPECT_NEAR(r.command.finger_force_n[1], 1.0, 1e-9);
  EXPECT_EQ(r.command.force_world_n, Vec3::Zero());
}

std::vector<DeviceInput> press_path() {
  std::vector<DeviceInput> path;
  for (int i = 0; i < 300; ++i) {
    const double t = i * 1e-3;
    path.push_back(at(Vec3(0.01 * std::sin(20 * t), 0.003 * t, 0.004 - 0.03 * t), t));
  }
  return path;
}

// A glove drives the tools: each finger tool sits at the virtual hand's fingertip for the
// tracker pose and the glove angles, and its force goes to its own finger actuator.
TEST(World, GloveFingertipsPlaceTheTools) {
  WorldDescription w = box_world(ContactResponse::kPenalty, 0.02, BodyKind::kStatic, 0.008);
  w.tools[0].name = "index";
  w.tools[0].finger = 1;
  ToolDescription middle = w.tools[0];
  middle.name = "middle";
  middle.finger = 2;
  w.tools.push_back(middle);
  w.has_hand = true;
  World world(w);
  DeviceInput in = at(Vec3(-0.1, -0.02, 0.05));
  in.q_world = Quat(Eigen::AngleAxisd(0.1, Vec3::UnitZ()));  // fingers along +x over the block
  in.joint_count = 15;
  in.joint_rad[3 + 1] = 0.9;  // index MCP flexion: curls the index down onto the block
  in.joint_rad[3 + 2] = 0.6;  // index PIP
  const StepResult& r = world.step(in, 1e-3);
  const HandModel hand(w.hand);
  GloveReading g;
  g.X_world_hand = Eigen::Translation3d(in.p_world) * in.q_world;
  g.angles_rad[1] = {0.0, 0.9, 0.6};
  const auto tips = hand.fingertips_world(g);
  EXPECT_NEAR((r.tools[0].p_world - tips[1]).norm(), 0.0, 1e-15);
  EXPECT_NEAR((r.tools[1].p_world - tips[2]).norm(), 0.0, 1e-15);
  // The curled index presses into the block's top (z = 0); the straight middle finger is above.
  ASSERT_LT(tips[1].z(), 0.008);
  ASSERT_GT(tips[2].z(), 0.008);
  EXPECT_GT(r.command.finger_force_n[1], 0.0);
  EXPECT_EQ(r.command.finger_force_n[2], 0.0);
  EXPECT_EQ(r.command.force_world_n, Vec3::Zero());  // a glove has no tip actuator

  WorldDescription bad = w;
  bad.tools[1].finger = -1;
  EXPECT_THROW(World{bad}, Error);
}

TEST(World, StepAllocatesNothing) {
  World world(sheet_world(0.004));
  const auto path = press_path();
  world.step(path[0], 1e-3);
  const long before = test::allocation_count();
  for (const DeviceInput& in : path) {
    world.step(in, 1e-3);
  }
  EXPECT_EQ(test::allocation_count() - before, 0);
  EXPECT_GT(world.current_deflection_m(0, 0), 0.0);  // the path did press in
}

TEST(World, ReplaysBitForBit) {
  const auto path = press_path();
  World a(box_world(ContactResponse::kPenalty, 0.02, BodyKind::kDeformable, 0.004));
  World b(box_world(ContactResponse::kPenalty, 0.02, BodyKind::kDeformable, 0.004));
  EXPECT_EQ(a.content_hash(), b.content_hash());
  for (const DeviceInput& in : path) {
    const Vec3 fa = a.step(in, 1e-3).command.force_world_n;
    const Vec3 fb = b.step(in, 1e-3).command.force_world_n;
    ASSERT_EQ(std::memcmp(fa.data(), fb.data(), sizeof(double) * 3), 0);
  }
}

TEST(World, BadDescriptionsAreNamed) {
  WorldDescription w = box_world(ContactResponse::kPenalty, 0.02, BodyKind::kStatic, 0.0);
  w.bodies[0].segments[0].material = 7;
  try {
    World world(std::move(w));
    FAIL() << "accepted a bad material index";
  } catch (const std::exception& e) {
    EXPECT_NE(std::string(e.what()).find("segment 'block'"), std::string::npos) << e.what();
  }
  WorldDescription empty = box_world(ContactResponse::kPenalty, 0.02, BodyKind::kStatic, 0.0);
  empty.bodies[0].segments[0].mesh = TriangleMesh{};
  EXPECT_THROW(World{std::move(empty)}, std::exception);
  // More tools than a cycle's record carries: refused, not silently left out of the accounting.
  WorldDescription crowded = box_world(ContactResponse::kPenalty, 0.02, BodyKind::kStatic, 0.0);
  crowded.tools.resize(static_cast<std::size_t>(kMaxTools) + 1, crowded.tools.front());
  try {
    World world(std::move(crowded));
    FAIL() << "accepted " << kMaxTools + 1 << " tools";
  } catch (const std::exception& e) {
    EXPECT_NE(std::string(e.what()).find("at most 8"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace hapsim
