// A teleoperation rig inside the one World: the step's stages move the slave, the ball and the
// sheet; reset() puts all three back where the description starts them, without allocating (a
// viewer's reset runs on the haptic thread), and the run after it is the fresh run's to the bit; an
// unusable master input holds the slave and sends no torque.
#include "hapsim/rig/rig_controller.h"
#include "hapsim/rig/rig_world.h"
#include "hapsim/world/world.h"
#include "hapsim/world/world_model.h"
#include "hapsim/world/world_state.h"

#include "hapsim/kinematics/procedural_motoman.h"

#include "support/allocation_counter.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <memory>

namespace hapsim {
namespace {

WorldDescription rig() {
  TeleopRigDescription d;
  d.slave = std::make_shared<const SerialChain>(make_procedural_motoman());
  d.environment.floor_z_m = 0.0;
  d.environment.X_world_sheet = Iso3(Eigen::Translation3d(0.5, 0.25, 0.05));
  d.ball_start_world = Vec3(0.5, 0.25, 0.2);  // above the sheet: it falls onto it
  return rig_world(std::move(d));
}

DeviceInput master(double base_rad) {
  DeviceInput in;
  in.joint_rad[0] = base_rad;
  in.joint_rad[1] = 0.3;
  in.joint_rad[2] = 0.6;
  in.joint_count = 3;
  in.finger_count = 2;
  return in;
}

TEST(WorldRig, BallFallsOnTheSheetAndResetPutsEverythingBack) {
  World world(rig());
  ASSERT_NE(rig_state(world), nullptr);
  const Vec3 start = world.body_pose(rig_description(world.description())->ball_body).translation();
  const auto q0 =
      std::vector<double>(rig_state(world)->slave->q().begin(), rig_state(world)->slave->q().end());
  for (int k = 0; k < 1500; ++k) {
    const StepResult& r = world.step(master(0.2), 1e-3);
    ASSERT_NE(rig_result(r), nullptr);
    ASSERT_TRUE(rig_result(r)->ball_p_world.allFinite());
  }
  // Fallen and resting on the dented sheet (sheet at z = 0.05, ball radius 0.03).
  EXPECT_LT(world.body_pose(rig_description(world.description())->ball_body).translation().z(),
            0.08 + 1e-3);
  EXPECT_GT(world.sheet(rig_description(world.description())->sheet_body)->max_depth_m(), 0.0);
  EXPECT_NEAR(world.last_result().time_s, 1.5, 1e-9);
  world.reset();
  EXPECT_EQ(world.body_pose(rig_description(world.description())->ball_body).translation(), start);
  EXPECT_EQ(world.sheet(rig_description(world.description())->sheet_body)->max_depth_m(), 0.0);
  const auto q = rig_state(world)->slave->q();
  EXPECT_TRUE(std::equal(q.begin(), q.end(), q0.begin()));
  EXPECT_EQ(rig_result(world.last_result()), &rig_state(world)->result);
}

TEST(WorldRig, ResetAllocatesNothingAndTheRunAfterItIsAFreshRun) {
  World fresh(rig());
  World world(rig());
  for (int k = 0; k < 800; ++k) {
    (void)world.step(master(0.1 + 1e-4 * k), 1e-3);
  }
  const long before = test::allocation_count();
  world.reset();
  EXPECT_EQ(test::allocation_count() - before, 0);
  for (int k = 0; k < 800; ++k) {
    (void)world.step(master(0.3 - 2e-4 * k), 1e-3);
    (void)fresh.step(master(0.3 - 2e-4 * k), 1e-3);
  }
  const std::size_t ball = rig_description(world.description())->ball_body;
  EXPECT_EQ(world.body_pose(ball).matrix(), fresh.body_pose(ball).matrix());
  EXPECT_EQ(rig_state(world)->slave->tip_pose().matrix(),
            rig_state(fresh)->slave->tip_pose().matrix());
  EXPECT_EQ(world.last_result().command.joint_torque_nm,
            fresh.last_result().command.joint_torque_nm);
}

// A master whose reading is unusable (NaN, or not healthy) moves nothing and is sent no torque;
// the slave brakes to rest at its acceleration limit and stands, as a real arm stops.
TEST(WorldRig, UnusableMasterInputStopsTheSlaveAndSendsNoTorque) {
  World world(rig());
  for (int k = 0; k < 50; ++k) {
    (void)world.step(master(0.2 + 2e-3 * k), 1e-3);
  }
  const SlaveFollower& slave = *rig_state(world)->slave;
  double fastest = 0.0;
  for (const double v : slave.velocity()) {
    fastest = std::max(fastest, std::abs(v));
  }
  ASSERT_GT(fastest, 0.0);  // moving when the master goes
  const double dv = SlaveFollowerOptions{}.max_joint_acceleration_per_s2 * 1e-3;
  DeviceInput bad = master(std::numeric_limits<double>::quiet_NaN());
  for (int k = 0; k < static_cast<int>(std::ceil(fastest / dv)); ++k) {
    const StepResult& r = world.step(bad, 1e-3);
    EXPECT_EQ(r.command.joint_count, 0);
    EXPECT_EQ(r.command.finger_count, 0);
  }
  for (const double v : slave.velocity()) {
    EXPECT_EQ(v, 0.0);
  }
  const Iso3 stood = slave.tip_pose();
  bad = master(0.2);
  bad.healthy = false;
  EXPECT_EQ(world.step(bad, 1e-3).command.joint_count, 0);
  EXPECT_TRUE(slave.tip_pose().isApprox(stood, 1e-12));
}

// The grasp report, observed from a step's result alone: both pads pressing the ball from opposite
// sides hold it; a pad off the ball for a step or two (a served slave jerked by a stalled cycle)
// lets nothing go; off for kReleaseAfterS it is a release, dated when the pad left.
TEST(WorldRig, APadOffTheBallForAStepIsNoRelease) {
  World world(rig());
  (void)world.step(master(0.2), 1e-3);
  RigState& state = const_cast<RigState&>(*rig_state(world));  // observe() is the test's to call
  const TeleopRigDescription& d = *state.description;
  // What the body-contact stage reports: each pad's push on the ball, its normal out of the pad.
  const auto contact = [&](std::size_t pad, double push_n) {
    BodyContact c;
    c.body = BodyIndex{d.ball_body};
    c.other_body = BodyIndex{d.pad_body[pad]};
    c.normal_world = pad == 0 ? Vec3(0.0, -1.0, 0.0) : Vec3(0.0, 1.0, 0.0);
    c.force_world_n = push_n * c.normal_world;
    return c;
  };
  const std::array<BodyContact, 2> both{contact(0, 20.0), contact(1, 20.0)};
  const std::array<BodyContact, 1> one{contact(0, 20.0)};
  StepResult step = world.last_result();
  const auto observe = [&](double time_s, std::span<const BodyContact> contacts) {
    step.time_s = time_s;
    step.body_contacts = contacts;
    // The pads' pushes, as the command stage reads them off the same contacts.
    state.result.gripper.pad_force_n = {20.0, contacts.size() == 2 ? 20.0 : 0.0};
    state.observe(world.model(), step);
    return state.result.gripper;
  };
  EXPECT_TRUE(observe(1.000, both).grasped_now);
  for (int k = 1; k <= 3; ++k) {  // one pad lifted for 3 ms: still held
    const GripperReport g = observe(1.000 + 1e-3 * k, one);
    EXPECT_TRUE(g.held);
    EXPECT_FALSE(g.released_now);
  }
  EXPECT_TRUE(observe(1.004, both).held);
  // Lifted for good at 1.005 s: held for 20 ms more, then released, dated 1.005 s.
  for (int k = 5; k < 25; ++k) {
    const GripperReport g = observe(1.000 + 1e-3 * k, one);
    EXPECT_TRUE(g.held) << k;
    EXPECT_FALSE(g.released_now) << k;
  }
  const GripperReport released = observe(1.025, one);
  EXPECT_FALSE(released.held);
  EXPECT_TRUE(released.released_now);
  EXPECT_DOUBLE_EQ(released.released_at_s, 1.005);
  EXPECT_FALSE(observe(1.026, one).released_now);  // said once
}

}  // namespace
}  // namespace hapsim
