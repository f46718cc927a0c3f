// The teleoperation scene end to end, unattended: the scripted master explores the ball, the
// slave (procedural Motoman, and the GP7 when its URDF is there) grasps it, lifts and carries it,
// lets go over the sheet, and the ball comes to rest on the sheet within 5 mm of the target spot,
// the sheet dented under it.
#include "hapsim/kinematics/procedural_motoman.h"
#include "hapsim/kinematics/urdf_chain.h"
#include "hapsim/rig/rig_controller.h"
#include "hapsim/rig/rig_world.h"
#include "hapsim/script/pick_and_place_trajectory.h"
#include "hapsim/world/world.h"

#include "hapsim/core/error.h"
#include "support/test_data.h"

#include <gtest/gtest.h>

#include <filesystem>
#include <memory>

namespace hapsim {
namespace {

struct Outcome {
  bool grasped = false;
  double grasp_time_s = -1.0;
  double release_time_s = -1.0;
  double ball_lift_m = 0.0;
  Vec3 ball_final = Vec3::Zero();
  double peak_grasp_force_n = 0.0;
  double final_sheet_depth_m = 0.0;
  double final_kinetic_energy_j = 0.0;
};

TeleopRigDescription scene(std::shared_ptr<const SerialChain> slave) {
  TeleopRigDescription d;
  d.slave = std::move(slave);
  d.environment.floor_z_m = 0.0;
  d.environment.X_world_sheet = Iso3(Eigen::Translation3d(0.5, 0.25, 0.05));  // on a frame
  d.ball_start_world = Vec3(0.5, -0.25, d.ball.radius_m);                     // on the floor
  return d;
}

Outcome run(TeleopRigDescription d, const PickAndPlaceScript& script) {
  const MasterArm master(d.master);
  const PickAndPlacePlan plan =
      make_pick_and_place_plan(script, master, d.mapping, d.follower.gripper_max_width_m);
  // Start the slave where the script starts (a cold IK once, outside the loop).
  const DeviceInput first = plan.trajectory.sample_at(0.0);
  const Iso3 start = slave_target(
      d.mapping,
      master.hand_pose({first.joint_rad[0], first.joint_rad[1], first.joint_rad[2]}).translation(),
      first.joint_rad[0]);
  std::vector<double> seed(static_cast<std::size_t>(d.slave->dof()), 0.0);
  d.slave_start_rad.assign(seed.size(), 0.0);
  EXPECT_TRUE(solve_ik(*d.slave, start, seed, d.slave_start_rad).reached);
  const double start_z = d.ball_start_world.z();
  World world(rig_world(std::move(d)));
  Outcome o;
  const double dt = 1e-3;
  const auto steps = static_cast<int>(plan.trajectory.end_time_s() / dt);
  for (int k = 1; k <= steps; ++k) {
    const TeleopStepResult& r = *rig_result(world.step(plan.trajectory.sample_at(k * dt), dt));
    EXPECT_TRUE(r.ball_p_world.allFinite());
    if (r.gripper.grasped_now && !o.grasped) {
      o.grasped = true;
      o.grasp_time_s = r.time_s;
    }
    if (r.gripper.released_now && o.release_time_s < 0.0) {
      o.release_time_s = r.time_s;
    }
    o.ball_lift_m = std::max(o.ball_lift_m, r.ball_p_world.z() - start_z);
    o.peak_grasp_force_n = std::max(o.peak_grasp_force_n, r.gripper.grasp_force_n());
    for (int j = 0; j < r.command.joint_count; ++j) {
      EXPECT_TRUE(std::isfinite(r.command.joint_torque_nm[static_cast<std::size_t>(j)]));
    }
  }
  o.ball_final = world.body_pose(rig_description(world.description())->ball_body).translation();
  o.final_sheet_depth_m =
      world.sheet(rig_description(world.description())->sheet_body)->max_depth_m();
  o.final_kinetic_energy_j =
      (0.5 * rig_description(world.description())->ball.mass_kg *
       world.state().bodies[rig_description(world.description())->ball_body].v_world.squaredNorm());
  return o;
}

void expect_pick_and_place(std::shared_ptr<const SerialChain> slave) {
  TeleopRigDescription d = scene(std::move(slave));
  PickAndPlaceScript script;
  script.pick_world = d.ball_start_world;
  script.place_world = Vec3(0.5, 0.25, 0.05 + d.ball.radius_m);
  const Outcome o = run(d, script);
  EXPECT_TRUE(o.grasped);
  EXPECT_GT(o.release_time_s, o.grasp_time_s);
  EXPECT_GT(o.ball_lift_m, 0.1);  // carried over the 5 cm frame with 12 cm clearance
  EXPECT_LT((o.ball_final.head<2>() - script.place_world.head<2>()).norm(), 0.005)
      << o.ball_final.transpose();
  EXPECT_NEAR(o.ball_final.z(), script.place_world.z(), 0.005);
  EXPECT_GT(o.final_sheet_depth_m, 1e-4);  // the sheet carries it
  EXPECT_LT(o.final_kinetic_energy_j, 1e-8);
  EXPECT_GT(o.peak_grasp_force_n, 1.0);
  EXPECT_LE(o.peak_grasp_force_n, d.gripper.max_force_n * 1.001);
}

TEST(PickAndPlace, ProceduralMotomanPlacesTheBallOnTheSheet) {
  expect_pick_and_place(std::make_shared<const SerialChain>(make_procedural_motoman()));
}

TEST(PickAndPlace, Gp7PlacesTheBallOnTheSheet) {
  const auto urdf = test::data_path("motoman_gp7/gp7.urdf");
  HAPSIM_SKIP_WITHOUT_DATA(std::filesystem::exists(urdf), "Motoman GP7 URDF not found at " << urdf);
  UrdfChainOptions o;
  o.load_collision_meshes = false;
  expect_pick_and_place(std::make_shared<const SerialChain>(load_urdf_chain(urdf, o)));
}

// A gripper too weak for the ball (friction μ·2·0.5 N = 0.8 N < 1.5 · its 0.98 N weight): the
// pads close on it at their force limit but friction cannot carry it — no grasp is reported and
// the ball is not lifted off the floor (held by friction alone, nothing attaches it).
TEST(PickAndPlace, AWeakGripperLiftsNothing) {
  TeleopRigDescription d = scene(std::make_shared<const SerialChain>(make_procedural_motoman()));
  d.gripper.max_force_n = 0.5;
  PickAndPlaceScript script;
  script.pick_world = d.ball_start_world;
  script.place_world = Vec3(0.5, 0.25, 0.05 + d.ball.radius_m);
  const Outcome o = run(d, script);
  EXPECT_FALSE(o.grasped);
  EXPECT_LT(o.ball_lift_m, 0.005);
  EXPECT_LT(o.ball_final.z(), d.ball.radius_m + 0.001) << "still on the floor";
  EXPECT_GT(o.peak_grasp_force_n, 0.4) << "the pads did press it";
}

TEST(PickAndPlace, OutOfReachScriptIsRefused) {
  PickAndPlaceScript script;
  script.place_world = Vec3(3.0, 0.0, 0.0);
  EXPECT_THROW((void)make_pick_and_place_plan(script, MasterArm{}, TeleopMapping{}, 0.1), Error);
  script = PickAndPlaceScript{};
  script.carry_s = 0.0;
  EXPECT_THROW((void)make_pick_and_place_plan(script, MasterArm{}, TeleopMapping{}, 0.1), Error);
}

}  // namespace
}  // namespace hapsim
