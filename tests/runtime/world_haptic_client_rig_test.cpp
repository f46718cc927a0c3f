// A teleoperation World on the real-time loop through the one world client: after a scripted
// pick-and-place start the snapshot the viewer reads is the world's state exactly (ball, slave
// joints and tool, sheet), the world went through exactly what an inline run with the same inputs
// goes through, a reader thread never sees a torn snapshot, the haptic thread allocates nothing,
// and a paused client holds the world.
#include "hapsim/rig/rig_controller.h"
#include "hapsim/runtime/world_haptic_client.h"

#include "hapsim/core/device_profile.h"
#include "hapsim/device/simulated_device.h"
#include "hapsim/scene/scene_file.h"
#include "hapsim/scene/teleop_setup.h"
#include "support/allocation_counting_client.h"

#include <gtest/gtest.h>

#include <atomic>
#include <chrono>
#include <filesystem>
#include <thread>

namespace hapsim {
namespace {

// The default teleop scene (procedural Motoman) with its scripted pick-and-place.
TeleopSetup pick_and_place_setup() {
  const SceneDescription scene =
      load_scene(std::filesystem::path(HAPSIM_SOURCE_DIR) / "scenes" / "teleop.json");
  return make_rig_setup(scene, std::nullopt, /*load_link_meshes=*/false);
}

TEST(WorldHapticClientRig, SnapshotMatchesTheWorldExactlyAfterTheLoop) {
  const TeleopSetup setup = pick_and_place_setup();
  World world(setup.description);
  SimulatedDevice device(device_profile("simulated"), setup.trajectory);
  WorldHapticClient client(world);
  HapticLoopOptions o;
  o.max_cycles = 300;
  HapticLoop loop(device, client, o);
  loop.start();
  loop.wait();
  EXPECT_NEAR(world.last_result().time_s, 300 * o.period_s, 1e-9);  // 300 steps
  TripleBuffer<WorldSnapshot>& buffer = *client.snapshots();
  ASSERT_TRUE(buffer.update());
  ASSERT_TRUE(buffer.read_slot().teleop.has_value());
  const WorldSnapshot& ws = buffer.read_slot();
  const TeleopSnapshot& s = *ws.teleop;
  EXPECT_EQ(s.cycle, 299u);
  // The ball and the sheet are bodies: the world snapshot's poses and surfaces carry them.
  const std::size_t ball = rig_description(world.description())->ball_body;
  EXPECT_TRUE(ws.body_poses_world[ball].isApprox(world.body_pose(ball), 0.0));
  const auto q = rig_state(world)->slave->q();
  ASSERT_EQ(s.slave_q.size(), q.size());
  for (std::size_t i = 0; i < q.size(); ++i) {
    EXPECT_EQ(s.slave_q[i], q[i]) << "joint " << i;
  }
  EXPECT_TRUE(s.X_world_tool.isApprox(rig_state(world)->slave->tip_pose(), 0.0));
  EXPECT_EQ(s.gripper_width_m, rig_state(world)->result.gripper.width_m);
  EXPECT_EQ(s.held, rig_state(world)->result.held);
  const auto heights =
      world.sheet(rig_description(world.description())->sheet_body)->surface_heights();
  const std::vector<float>& sheet_xyz =
      ws.positions_body[world
                            .flat_segment(
                                BodyIndex{rig_description(world.description())->sheet_body},
                                LocalSegment{0})
                            .index()];
  ASSERT_EQ(sheet_xyz.size(), 3 * heights.size());
  for (std::size_t k = 0; k < heights.size(); ++k) {
    ASSERT_EQ(sheet_xyz[3 * k + 2], static_cast<float>(heights[k])) << "node " << k;
  }
  // The snapshot is one cycle's: the master joints the world followed are that cycle's input.
  for (std::size_t j = 0; j < 3; ++j) {
    EXPECT_EQ(s.master_joint_rad[j], s.input.joint_rad[j]);
  }
  EXPECT_EQ(s.input.joint_rad[0], setup.trajectory.sample_at(299 * o.period_s).joint_rad[0]);
  EXPECT_EQ(s.output.joint_count, 5);

  // The same inputs stepped inline give the same world, bit for bit.
  World inline_world(setup.description);
  for (std::uint64_t i = 0; i < 300; ++i) {
    static_cast<void>(inline_world.step(
        setup.trajectory.sample_at(static_cast<double>(i) * o.period_s), o.period_s));
  }
  EXPECT_EQ(
      inline_world.body_pose(rig_description(inline_world.description())->ball_body).translation(),
      world.body_pose(rig_description(world.description())->ball_body).translation());
  for (std::size_t i = 0; i < q.size(); ++i) {
    EXPECT_EQ(rig_state(inline_world)->slave->q()[i], q[i]) << "joint " << i;
  }
  EXPECT_EQ(rig_state(inline_world)->slave->gripper_width_m(),
            rig_state(world)->slave->gripper_width_m());
}

TEST(WorldHapticClientRig, ReaderSeesConsistentSnapshotsAndHapticThreadDoesNotAllocate) {
  const TeleopSetup setup = pick_and_place_setup();
  World world(setup.description);
  SimulatedDevice device(device_profile("simulated"), setup.trajectory);
  WorldHapticClient client(world);

  // Counts the haptic thread's allocations around the real client (step and after_cycle).
  test::AllocationCountingClient counting(client);

  HapticLoopOptions o;
  o.max_cycles = 300;
  HapticLoop loop(device, counting, o);
  std::atomic<int> inconsistent{0};
  std::atomic<int> snapshots{0};
  loop.start();
  std::thread viewer([&] {
    std::uint64_t last_cycle = 0;
    while (loop.running()) {
      if (client.snapshots()->update()) {
        const WorldSnapshot& ws = client.snapshots()->read_slot();
        const TeleopSnapshot& s = *ws.teleop;
        // One cycle's data: the master joints the world followed are that cycle's input.
        if (s.master_joint_rad[0] != s.input.joint_rad[0] ||
            s.master_joint_rad[2] != s.input.joint_rad[2] || s.cycle < last_cycle ||
            !ws.body_poses_world[rig_description(world.description())->ball_body]
                 .translation()
                 .allFinite()) {
          inconsistent.fetch_add(1);
        }
        last_cycle = s.cycle;
        snapshots.fetch_add(1);
      }
      std::this_thread::sleep_for(std::chrono::microseconds(300));
    }
  });
  viewer.join();
  loop.wait();
  EXPECT_EQ(counting.steps(), 300);
  EXPECT_EQ(counting.allocations(), 0) << "the haptic thread allocated";
  EXPECT_EQ(inconsistent.load(), 0);
  EXPECT_GT(snapshots.load(), 10);
}

TEST(WorldHapticClientRig, PausedClientHoldsTheWorldAndSendsNoTorque) {
  const TeleopSetup setup = pick_and_place_setup();
  World world(setup.description);
  SimulatedDevice device(device_profile("simulated"), setup.trajectory);
  WorldHapticClient client(world);
  client.set_paused(true);
  EXPECT_TRUE(client.paused());
  HapticLoopOptions o;
  o.max_cycles = 50;
  HapticLoop loop(device, client, o);
  loop.start();
  loop.wait();
  EXPECT_EQ(rig_state(world)->result.time_s, 0.0);  // never stepped
  ASSERT_TRUE(client.snapshots()->update());
  const TeleopSnapshot& s = *client.snapshots()->read_slot().teleop;
  EXPECT_EQ(s.cycle, 49u);
  EXPECT_EQ(client.snapshots()
                ->read_slot()
                .body_poses_world[rig_description(setup.description)->ball_body]
                .translation(),
            rig_description(setup.description)->ball_start_world);
  for (int j = 0; j < kMaxDeviceJoints; ++j) {
    EXPECT_EQ(s.output.joint_torque_nm[static_cast<std::size_t>(j)], 0.0);
  }
}

}  // namespace
}  // namespace hapsim
