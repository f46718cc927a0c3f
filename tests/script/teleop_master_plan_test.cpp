// The teleoperation scene's scripted master planned on its rig
// (script/teleop_pick_and_place_plan.h) and the slave's start (script/slave_start.h): the plan
// picks the ball where the rig starts it and the slave's start joints put its flange where the
// master's first pose asks.
#include "hapsim/kinematics/procedural_motoman.h"
#include "hapsim/kinematics/slave_follower.h"
#include "hapsim/script/master_flange_ik.h"
#include "hapsim/script/slave_start.h"
#include "hapsim/script/teleop_pick_and_place_plan.h"

#include <gtest/gtest.h>

#include <array>
#include <limits>
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

// A master script is solved sample by sample from the last solution. With the solver's 0.1 mm
// tolerance a slow press left the joints where they were until the path had moved 0.1 mm away,
// then jumped: the master (and the slave after it) moved in 0.2 mm steps every 3-4 ms, velocity
// spikes of 0.2 m/s that a served master rendered through the tissue's damping (2026-11-29). Each
// sample now puts the flange where it was asked, to a micrometre, so the path keeps its speed.
TEST(TeleopMasterPlan, ASlowPressMovesTheMasterEverySampleNotInSteps) {
  const TeleopRigDescription d = motoman_rig();
  const MasterArm master(d.master);
  MasterFlangeIk ik(master, d.mapping, d.follower.gripper_max_width_m, "a slow press");
  const Vec3 start(0.5, 0.0, 0.25);
  Vec3 previous_flange = Vec3::Constant(std::numeric_limits<double>::quiet_NaN());
  for (int k = 0; k <= 400; ++k) {  // 20 mm down at 0.05 m/s, sampled at 1 kHz
    const Vec3 asked = start - Vec3::UnitZ() * (0.05e-3 * k);
    const DeviceInput in = ik.input_for(1e-3 * k, asked, 0.0);
    const std::array<double, 3> q{in.joint_rad[0], in.joint_rad[1], in.joint_rad[2]};
    const Vec3 flange =
        slave_target(d.mapping, master.hand_pose(q).translation(), q[0]).translation();
    ASSERT_LT((flange - asked).norm(), 2e-6) << "sample " << k;
    if (k > 0) {
      // Every sample moves it by the path's 0.05 mm: never a pause and then a double step.
      ASSERT_NEAR((flange - previous_flange).norm(), 0.05e-3, 4e-6) << "sample " << k;
    }
    previous_flange = flange;
  }
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
