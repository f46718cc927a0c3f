#include "hapsim/scene/teleop_setup.h"

#include "hapsim/core/error.h"
#include "hapsim/kinematics/master_arm.h"
#include "hapsim/kinematics/procedural_motoman.h"
#include "hapsim/kinematics/urdf_chain.h"
#include "hapsim/rig/rig_controller.h"
#include "hapsim/rig/rig_world.h"
#include "hapsim/script/scene_palpation_plan.h"
#include "hapsim/script/slave_start.h"
#include "hapsim/script/teleop_pick_and_place_plan.h"
#include "hapsim/script/teleop_probe_plan.h"
#include "hapsim/world/world.h"

#include <algorithm>
#include <memory>
#include <utility>

namespace hapsim {

namespace {

std::size_t body_index(const WorldDescription& w, const std::string& name) {
  for (std::size_t b = 0; b < w.bodies.size(); ++b) {
    if (w.bodies[b].name == name) {
      return b;
    }
  }
  return TeleopRigDescription::kNoBody;
}

// The rig a scene describes: its slave (procedural or URDF), mapping and gripper, and the scene's
// bodies and tool it reads; the ball's size, mass and start and the sheet's grid and pose are
// those of their bodies (scene/rig_reader.h checked the ball is a sphere, the sheet a sheet).
TeleopRigDescription rig_from_scene(const SceneDescription& scene, bool load_link_meshes) {
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
  d.follower.max_joint_acceleration_per_s2 = t.slave_max_acceleration_per_s2;
  d.force_scale = t.force_scale;
  const WorldDescription& w = scene.world;
  d.ball_body = t.ball_body.empty() ? TeleopRigDescription::kNoBody : body_index(w, t.ball_body);
  d.sheet_body = t.sheet_body.empty() ? TeleopRigDescription::kNoBody : body_index(w, t.sheet_body);
  d.floor_body = t.floor_body.empty() ? TeleopRigDescription::kNoBody : body_index(w, t.floor_body);
  d.ball.gravity_m_per_s2 = w.gravity_m_per_s2;
  if (d.ball_body != TeleopRigDescription::kNoBody) {
    const BodyDescription& ball = w.bodies[d.ball_body];
    const ExactSphere& sphere = *ball.segments.front().sphere;
    d.ball.mass_kg = ball.rigid.mass_kg;
    d.ball.radius_m = sphere.radius_m;
    d.ball_start_world = ball.X_world_body * sphere.center_body;
  }
  // The floor the viewer stands the master on: the top of the floor body, if any.
  d.environment.has_floor = d.floor_body != TeleopRigDescription::kNoBody;
  if (d.environment.has_floor) {
    const BodyDescription& floor = w.bodies[d.floor_body];
    double top_z = -kInf;
    for (const SegmentDescription& segment : floor.segments) {
      for (const Vec3& p_body : segment.mesh.vertices) {
        top_z = std::max(top_z, (floor.X_world_body * p_body).z());
      }
    }
    d.environment.floor_z_m = top_z;
  }
  if (d.sheet_body != TeleopRigDescription::kNoBody) {
    const BodyDescription& sheet = w.bodies[d.sheet_body];
    d.sheet = sheet.sheet;
    d.environment.X_world_sheet = sheet.X_world_body;
  }
  for (std::size_t i = 0; i < w.tools.size(); ++i) {
    if (!t.carried_tool.empty() && w.tools[i].name == t.carried_tool) {
      d.carried_tool = i;
    }
  }
  return d;
}

// The master's scripted tele-palpation: the scene's palpation planned for the carried tool's
// centre on the scene's bodies (rigid: aiming needs their rest surfaces only), then carried by
// the slave (script/teleop_probe_plan.h).
Trajectory rig_palpation(const SceneDescription& scene, const TeleopRigDescription& d,
                         const MasterArm& master) {
  if (d.carried_tool == TeleopRigDescription::kNoTool) {
    throw Error(scene.file.string() + ":/rig",
                "a palpation script needs the tool the slave carries ('carries_tool')");
  }
  WorldDescription aim = scene.world;
  for (BodyDescription& b : aim.bodies) {
    if (b.kind == BodyKind::kDeformable) {
      b.kind = BodyKind::kStatic;
      b.fem.reset();
    }
  }
  // The plan is for the first tool's centre: the carried tool, where it is.
  const ToolDescription carried = aim.tools[d.carried_tool];
  aim.tools = {carried};
  aim.tools.front().offset_device = Vec3::Zero();
  const World aim_world(std::move(aim));
  const PalpationPlan probe = make_scene_palpation(aim_world, scene.device.palpation);
  return make_teleop_probe_plan(probe.trajectory, d, master, carried.offset_device);
}

// The slave starts where the master's first pose asks it to be (one cold IK, before the run).
void solve_start(const SceneDescription& scene, TeleopRigDescription& d, const MasterArm& master,
                 const Trajectory& trajectory) {
  if (!solve_slave_start(d, master, trajectory)) {
    throw Error(scene.file.string(),
                "the master's first pose puts the slave's target out of its reach");
  }
}

Trajectory master_trajectory_file(const std::filesystem::path& file) {
  Trajectory t = load_trajectory_csv(file);
  if (t.joint_count < 3 || t.finger_count < 2) {
    throw Error(file.string(),
                "a master trajectory needs joint columns j0..j2 (base, shoulder, elbow) and "
                "finger columns f0, f1");
  }
  return t;
}

}  // namespace

TeleopSetup make_rig_setup(const SceneDescription& scene,
                           const std::optional<std::filesystem::path>& trajectory,
                           bool load_link_meshes) {
  TeleopSetup s;
  TeleopRigDescription d = rig_from_scene(scene, load_link_meshes);
  const TeleopSceneDescription& t = scene.teleop;
  const MasterArm master(d.master);
  if (trajectory || !scene.device.trajectory_file.empty()) {
    const std::filesystem::path file = trajectory ? *trajectory : scene.device.trajectory_file;
    s.trajectory = master_trajectory_file(file);
    s.device_name = "simulated master (trajectory " + file.string() + ")";
  } else if (scene.device.has_pick_and_place) {
    if (d.ball_body == TeleopRigDescription::kNoBody) {
      throw Error(scene.file.string() + ":/device/pick_and_place",
                  "a pick-and-place needs the rig's 'ball' (a dynamic sphere it picks)");
    }
    s.trajectory = make_teleop_pick_and_place(scene.device.pick_and_place, d, master).trajectory;
    s.has_target = true;
    s.target_world = scene.device.pick_and_place.place_m;
    s.device_name = "simulated master (scripted pick-and-place)";
  } else if (scene.device.has_palpation) {
    s.trajectory = rig_palpation(scene, d, master);
    s.device_name = "simulated master (scripted tele-palpation)";
  } else {
    throw Error(scene.file.string() + ":/device",
                "a rig scene's device is the master: give it a 'trajectory' of master joints, a "
                "'pick_and_place' of the rig's ball or a 'palpation' script for the tool the "
                "slave carries");
  }
  solve_start(scene, d, master, s.trajectory);
  s.slave_name = t.slave_urdf.empty() ? "procedural Motoman" : t.slave_urdf.string();
  // Built with the start joints: the slave's bodies start where its follower does.
  s.description = add_rig(scene.world, std::move(d));
  return s;
}

}  // namespace hapsim
