// The viewer's teleoperation session without a window (a ViewerSession never touches GL): the
// scripted master runs the procedural Motoman scene on the real-time loop and the readout follows
// it; the mouse probe is the master's hand — its position becomes master joints whose hand pose
// is the probe's, and the slave's tool goes where the mapping sends that hand; the hand-to-joints
// mapping reaches what the arm reaches, maps the grasp button onto the fingers and allocates
// nothing on the haptic thread.
#include "hapsim/device/master_probe_device.h"
#include "hapsim/rig/rig_controller.h"
#include "hapsim/ui/viewer_scenes.h"

#include "hapsim/device/interactive_device.h"
#include "hapsim/scene/scene_file.h"
#include "hapsim/scene/teleop_setup.h"
#include "support/allocation_counter.h"
#include "support/replay_check.h"

#include <gtest/gtest.h>

#include <chrono>
#include <cmath>
#include <stdexcept>
#include <string>
#include <thread>

namespace hapsim {
namespace {

const std::filesystem::path kScene =
    std::filesystem::path(HAPSIM_SOURCE_DIR) / "scenes/teleop.json";

const BodyDescription& body_named(const WorldDescription& world, const std::string& name) {
  for (const BodyDescription& b : world.bodies) {
    if (b.name == name) {
      return b;
    }
  }
  throw std::runtime_error("no body named " + name);
}

ViewerConfig config_for(const std::string& device) {
  ViewerConfig c;
  c.scene = kScene;
  c.device = device;
  return c;
}

const std::string* line(const SessionReadout& r, const std::string& label) {
  for (const auto& [l, v] : r.lines) {
    if (l == label) {
      return &v;
    }
  }
  return nullptr;
}

const ToolReadout* tool(const SessionReadout& r, const std::string& name) {
  for (const ToolReadout& t : r.tools) {
    if (t.name == name) {
      return &t;
    }
  }
  return nullptr;
}

void run_for(ViewerSession& session, double seconds) {
  const auto end = std::chrono::steady_clock::now() + std::chrono::duration<double>(seconds);
  while (std::chrono::steady_clock::now() < end) {
    std::this_thread::sleep_for(std::chrono::milliseconds(16));
    session.update();
  }
}

// Updates the session (a frame every 16 ms) until its loop has stepped `sim_seconds` more of
// simulated time: what the assertions after it need, however slow the machine (a sanitizer build
// steps several times slower than real time). Gives up after 120 s of wall-clock time, and the
// assertions that follow then say what was missing.
void run_simulated(ViewerSession& session, double sim_seconds) {
  session.update();
  const double until_s = session.readout().time_s + sim_seconds;
  const auto give_up = std::chrono::steady_clock::now() + std::chrono::seconds(120);
  while (session.readout().time_s < until_s && std::chrono::steady_clock::now() < give_up) {
    std::this_thread::sleep_for(std::chrono::milliseconds(16));
    session.update();
  }
}

std::array<double, 3> first_arm_rad(const TeleopSetup& setup) {
  const DeviceInput first = setup.trajectory.sample_at(setup.trajectory.start_time_s());
  return {first.joint_rad[0], first.joint_rad[1], first.joint_rad[2]};
}

TEST(TeleopViewerSession, ScriptedMasterRunsOnTheLoopAndFillsTheReadout) {
  const SceneDescription scene = load_scene(kScene);
  const std::unique_ptr<ViewerSession> session = make_viewer_session(config_for("sim"), scene);
  EXPECT_EQ(session->mouse_device(), nullptr);
  EXPECT_GT(session->render_scene().mesh_count(), 0u);
  EXPECT_TRUE(session->bounds_world().volume() > 0.0);
  run_simulated(*session, 1.1);
  const SessionReadout& r = session->readout();
  EXPECT_GT(r.time_s, 1.0);
  ASSERT_NE(line(r, "ball (mm)"), nullptr);
  EXPECT_NE(line(r, "sheet deepest dent (mm)"), nullptr);
  EXPECT_NE(line(r, "slave joints (deg)"), nullptr);
  EXPECT_NE(line(r, "master torques (N·m)"), nullptr);
  ASSERT_EQ(r.bars.size(), 3u);
  EXPECT_EQ(r.bars[0].first, "grasp");
  EXPECT_DOUBLE_EQ(r.bar_full_scale_n, scene.teleop.gripper_max_force_n);
  ASSERT_NE(tool(r, "slave tool"), nullptr);
  ASSERT_NE(tool(r, "master hand"), nullptr);
  // The script hovers above the ball first: the tool is above it, within the reach of the arm.
  const Vec3 p_tool = tool(r, "slave tool")->p_world;
  const Vec3 ball_start = body_named(scene.world, "ball").X_world_body.translation();
  EXPECT_GT(p_tool.z(), ball_start.z());
  EXPECT_LT((p_tool - ball_start).head<2>().norm(), 0.05);
  EXPECT_GT(session->loop_status().cycles, 1000u);
  EXPECT_GT(session->render_scene().mesh_count(), 0u);

  // Recording works for a rig as for the knee: from the scene's start, replayable bit for bit.
  std::string error;
  const auto file = std::filesystem::temp_directory_path() /
                    ("hapsim_view_rig_" + std::to_string(::getpid()) + ".rec");
  ASSERT_TRUE(session->set_recording(&file, error)) << error;
  run_for(*session, 0.3);
  ASSERT_TRUE(session->set_recording(nullptr, error));
  EXPECT_TRUE(test::replays_bit_for_bit(scene, file));
  std::filesystem::remove(file);

  // Reset starts the script again from its first cycle.
  session->reset();
  run_for(*session, 0.2);
  EXPECT_LT(session->readout().time_s, 0.6);
}

TEST(TeleopViewerSession, MouseProbeIsTheSlaveToolsTargetAndTheSlaveFollowsIt) {
  const SceneDescription scene = load_scene(kScene);
  const TeleopSetup setup = make_rig_setup(scene, std::nullopt, false);
  const std::unique_ptr<ViewerSession> session = make_viewer_session(config_for("mouse"), scene);
  InteractiveDevice* mouse = session->mouse_device();
  ASSERT_NE(mouse, nullptr);
  const MasterArm master(rig_description(setup.description)->master);
  const Vec3 p0 = session->probe_start_world();
  const Vec3 hand0 = master.hand_pose(first_arm_rad(setup)).translation();
  // The probe starts on the slave tool's target for the master's first pose.
  const Vec3 start_target =
      slave_target(rig_description(setup.description)->mapping, hand0, first_arm_rad(setup)[0])
          .translation();
  EXPECT_LT((p0 - start_target).norm(), 1e-9);

  // At the start the slave is still, at its solved start pose.
  run_simulated(*session, 0.2);
  const Vec3 tool0 = tool(session->readout(), "slave tool")->p_world;
  EXPECT_LT((tool0 - start_target).norm(), 1e-3);

  // A 2 cm move of the probe (the viewer feeds MouseProbe::input() each frame).
  DeviceInput in;
  in.p_world = p0 + Vec3(0.0, 0.02, 0.0);
  mouse->set_input(in);
  run_simulated(*session, 1.0);
  const SessionReadout& r = session->readout();

  // Independent: the same conversion, then the master's and the slave's geometry.
  MasterHandMapping mapping(master, first_arm_rad(setup));
  mapping.set_probe_in_slave_frame(rig_description(setup.description)->mapping);
  const DeviceInput converted = mapping.master_input(in);
  ASSERT_EQ(converted.joint_count, 3);
  const std::array<double, 3> q{converted.joint_rad[0], converted.joint_rad[1],
                                converted.joint_rad[2]};
  const Vec3 hand = master.hand_pose(q).translation();
  EXPECT_LT((tool(r, "master hand")->p_world - hand).norm(), 1e-3);
  const Vec3 target =
      slave_target(rig_description(setup.description)->mapping, hand, q[0]).translation();
  // The slave's target is where the cursor put the probe (the master reaches it).
  EXPECT_LT((target - in.p_world).norm(), 1e-3);
  const Vec3 tool1 = tool(r, "slave tool")->p_world;
  EXPECT_LT((tool1 - target).norm(), 3e-3)
      << "tool " << tool1.transpose() << " target " << target.transpose();
  // The gripper follows the cursor one to one: a 2 cm probe move is a 2 cm tool move.
  EXPECT_NEAR((tool1 - tool0).norm(), 0.02, 3e-3);
}

TEST(MasterHandMapping, HandLandsOnReachableProbePositionsAndGraspFollowsTheButton) {
  const SceneDescription scene = load_scene(kScene);
  const TeleopSetup setup = make_rig_setup(scene, std::nullopt, false);
  const MasterArm master(rig_description(setup.description)->master);
  MasterHandMapping mapping(master, first_arm_rad(setup));
  const Vec3 p0 = master.hand_pose(first_arm_rad(setup)).translation();
  // A drag: small steps along a loop around the start, as the viewer sends them frame by frame.
  for (int k = 0; k <= 120; ++k) {
    const double a = 2.0 * 3.141592653589793 * k / 120.0;
    DeviceInput in;
    in.p_world = p0 + Vec3(0.06 * std::sin(a), 0.08 * (1.0 - std::cos(a)), -0.04 * std::sin(a));
    const DeviceInput out = mapping.master_input(in);
    ASSERT_TRUE(mapping.reached()) << "step " << k;
    const std::array<double, 3> q{out.joint_rad[0], out.joint_rad[1], out.joint_rad[2]};
    ASSERT_LT((master.hand_pose(q).translation() - in.p_world).norm(), 1e-3) << "step " << k;
    for (std::size_t j = 0; j < 3; ++j) {
      EXPECT_GE(q[j], master.geometry().lower_rad[j] - 1e-12);
      EXPECT_LE(q[j], master.geometry().upper_rad[j] + 1e-12);
    }
  }
  // Out of reach: the best pose, finite, no throw.
  DeviceInput far;
  far.p_world = Vec3(3.0, 0.0, 0.2);
  const DeviceInput stretched = mapping.master_input(far);
  EXPECT_FALSE(mapping.reached());
  EXPECT_TRUE(std::isfinite(stretched.joint_rad[0]) && std::isfinite(stretched.joint_rad[1]));

  // Grasp: open is the master's widest opening, closed is angle 0.
  DeviceInput open;
  open.p_world = p0;
  const DeviceInput o = mapping.master_input(open);
  EXPECT_EQ(o.finger_count, 2);
  EXPECT_NEAR(o.finger_rad[0], master.geometry().finger_open_limit_rad, 1e-9);
  EXPECT_EQ(o.finger_rad[0], o.finger_rad[1]);
  DeviceInput closed = open;
  closed.buttons = 1U;
  const DeviceInput c = mapping.master_input(closed);
  EXPECT_EQ(c.finger_rad[0], 0.0);
  EXPECT_EQ(c.finger_rad[1], 0.0);
  EXPECT_EQ(c.buttons, 1U);
  // The probe's glove joints are dropped.
  EXPECT_EQ(c.joint_count, 3);
  EXPECT_EQ(c.joint_rad[5], 0.0);
}

TEST(MasterHandMapping, ConvertingAllocatesNothing) {
  const SceneDescription scene = load_scene(kScene);
  const TeleopSetup setup = make_rig_setup(scene, std::nullopt, false);
  const MasterArm master(rig_description(setup.description)->master);
  MasterHandMapping mapping(master, first_arm_rad(setup));
  const Vec3 p0 = master.hand_pose(first_arm_rad(setup)).translation();
  DeviceInput in;
  const long before = test::allocation_count();
  double sum = 0.0;
  for (int k = 0; k < 200; ++k) {
    in.p_world = p0 + Vec3(0.0005 * k, 0.0, 0.0);
    sum += mapping.master_input(in).joint_rad[1];
  }
  in.p_world = Vec3(5.0, 5.0, 5.0);  // out of reach: every restart runs
  sum += mapping.master_input(in).joint_rad[1];
  EXPECT_EQ(test::allocation_count(), before);
  EXPECT_TRUE(std::isfinite(sum));
}

}  // namespace
}  // namespace hapsim
