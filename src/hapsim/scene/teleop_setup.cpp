#include "hapsim/scene/teleop_setup.h"

#include "hapsim/core/error.h"
#include "hapsim/kinematics/master_arm.h"
#include "hapsim/kinematics/procedural_motoman.h"
#include "hapsim/kinematics/urdf_chain.h"
#include "hapsim/rig/rig_controller.h"
#include "hapsim/rig/rig_world.h"
#include "hapsim/script/slave_start.h"
#include "hapsim/script/teleop_pick_and_place_plan.h"

#include <memory>
#include <utility>

namespace hapsim {

namespace {

TeleopRigDescription rig_description(const SceneDescription& scene, bool load_link_meshes) {
  const TeleopSceneDescription& t = scene.teleop;
  TeleopRigDescription d;
  if (t.slave_urdf.empty()) {
    d.slave = std::make_shared<const SerialChain>(make_procedural_motoman());
  } else {
    UrdfChainOptions o;
    o.tip_link = t.slave_tip;
    o.load_collision_meshes = load_link_meshes;
    d.slave = std::make_shared<const SerialChain>(load_urdf_chain(t.slave_urdf, o));
  }
  d.mapping.scale = t.scale;
  d.mapping.X_slave_master = Iso3(Eigen::Translation3d(t.offset_m));
  d.gripper.max_force_n = t.gripper_max_force_n;
  d.follower.gripper_max_width_m = t.gripper_max_width_m;
  d.follower.gripper_speed_m_per_s = t.gripper_speed_m_per_s;
  d.ball.mass_kg = t.ball_mass_kg;
  d.ball.radius_m = t.ball_radius_m;
  d.ball_start_world = t.ball_start_m;
  d.sheet.nodes_per_side = t.sheet_nodes_per_side;
  d.sheet.side_m = t.sheet_size_m;
  d.environment.X_world_sheet = Iso3(Eigen::Translation3d(t.sheet_position_m));
  d.environment.floor_z_m = t.floor_z_m;
  return d;
}

}  // namespace

TeleopSetup make_teleop_setup(const SceneDescription& scene,
                              const std::optional<std::filesystem::path>& trajectory,
                              bool load_link_meshes) {
  TeleopSetup s;
  TeleopRigDescription d = rig_description(scene, load_link_meshes);
  const MasterArm master(d.master);
  if (trajectory || !scene.device.has_pick_and_place) {
    const std::filesystem::path file = trajectory ? *trajectory : scene.device.trajectory_file;
    s.trajectory = load_trajectory_csv(file);
    if (s.trajectory.joint_count < 3 || s.trajectory.finger_count < 2) {
      throw Error(file.string(),
                  "a master trajectory needs joint columns j0..j2 (base, shoulder, elbow) and "
                  "finger columns f0, f1");
    }
    s.device_name = "simulated master (trajectory " + file.string() + ")";
  } else {
    s.trajectory = make_teleop_pick_and_place(scene.device.pick_and_place, d, master).trajectory;
    s.has_target = true;
    s.target_world = scene.device.pick_and_place.place_m;
    s.device_name = "simulated master (scripted pick-and-place)";
  }

  // The slave starts where the master's first pose asks it to be (one cold IK, before the run).
  if (!solve_slave_start(d, master, s.trajectory)) {
    throw Error(scene.file.string(),
                "the master's first pose puts the slave's target out of its reach");
  }
  s.slave_name =
      scene.teleop.slave_urdf.empty() ? "procedural Motoman" : scene.teleop.slave_urdf.string();
  // Built with the start joints: the slave's bodies start where its follower does.
  s.description = rig_world(std::move(d));
  return s;
}

}  // namespace hapsim
