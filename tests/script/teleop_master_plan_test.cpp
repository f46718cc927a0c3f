// The teleoperation scene's scripted master planned on its rig
// (script/teleop_pick_and_place_plan.h) and the slave's start (script/slave_start.h): the plan
// picks the ball where the rig starts it and the slave's start joints put its flange where the
// master's first pose asks.
#include "hapsim/kinematics/procedural_motoman.h"
#include "hapsim/kinematics/slave_follower.h"
#include "hapsim/script/slave_start.h"
#include "hapsim/script/teleop_pick_and_place_plan.h"

#include <gtest/gtest.h>

#include <memory>

namespace hapsim {
namespace {

TeleopRigDescription motoman_rig() {
  TeleopRigDescription d;
  d.slave = std::make_shared<const SerialChain>(make_procedural_motoman());
  d.ball_start_world = Vec3(0.5, -0.25, d.ball.radius_m);
  return d;
}

TEST(TeleopMasterPlan, PicksWhereTheRigStartsTheBallAndEndsAtThePlace) {
  const TeleopRigDescription d = motoman_rig();
  const MasterArm master(d.master);
  PickAndPlaceDescription description;
  description.carry_s = 1.0;
  const PickAndPlacePlan plan = make_teleop_pick_and_place(description, d, master);
  ASSERT_FALSE(plan.trajectory.samples.empty());
  ASSERT_FALSE(plan.phases.empty());
  EXPECT_EQ(plan.phases.front().name, "hover");
  // The carry takes the description's time.
  for (const PickAndPlacePhase& p : plan.phases) {
    if (p.name == "carry") {
      EXPECT_NEAR(p.end_s - p.start_s, description.carry_s, 1e-9);
    }
  }
}

TEST(TeleopMasterPlan, SlaveStartPutsTheFlangeWhereTheMastersFirstPoseAsks) {
  TeleopRigDescription d = motoman_rig();
  const MasterArm master(d.master);
  const Trajectory trajectory =
      make_teleop_pick_and_place(PickAndPlaceDescription{}, d, master).trajectory;
  ASSERT_TRUE(solve_slave_start(d, master, trajectory));
  ASSERT_EQ(d.slave_start_rad.size(), static_cast<std::size_t>(d.slave->dof()));
  const DeviceInput first = trajectory.sample_at(trajectory.start_time_s());
  const Iso3 target = slave_target(
      d.mapping,
      master.hand_pose({first.joint_rad[0], first.joint_rad[1], first.joint_rad[2]}).translation(),
      first.joint_rad[0]);
  EXPECT_LT((d.slave->forward(d.slave_start_rad).translation() - target.translation()).norm(),
            1e-3);
}

TEST(TeleopMasterPlan, SlaveStartOutOfReachIsFalse) {
  TeleopRigDescription d = motoman_rig();
  d.mapping.X_slave_master = Iso3(Eigen::Translation3d(10.0, 0.0, 0.0));  // 10 m away
  const MasterArm master(d.master);
  DeviceInput in;
  in.joint_count = 3;
  const Trajectory trajectory = make_trajectory({in}, 0, 3, "test");
  EXPECT_FALSE(solve_slave_start(d, master, trajectory));
}

}  // namespace
}  // namespace hapsim
