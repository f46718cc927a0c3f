// The device host's cycle (net/device_host_client.h) against a simulation side played by the test
// over real DDS on loopback: the client publishes its states; a model answering one of them is
// rendered at the device's own position, F = f0 + K·(x0 − x) moved by how far the device went
// since (against the analytic value), after the blend-in; a model answering the simulation's own
// script (device sequence 0) is never rendered; and the cycle allocates nothing.
#include "hapsim/net/device_host_client.h"
#include "hapsim/kinematics/procedural_motoman.h"
#include "hapsim/net/device_state_gate.h"
#include "hapsim/net/local_model_codec.h"
#include "hapsim/rig/rig_controller.h"

#include "net/net_test_support.h"
#include "support/allocation_counter.h"

#include <array>
#include <chrono>
#include <memory>
#include <optional>
#include <string>
#include <thread>

#include <gtest/gtest.h>

namespace hapsim::net {
namespace {

constexpr dds_domainid_t kDomain = 79;
constexpr std::uint64_t kHash = 0xfeedULL;

class DeviceHostClientTest : public ::testing::Test {
 protected:
  // What the host is told: a fixture for another device overrides these.
  [[nodiscard]] virtual DeviceHostOptions options() const { return {}; }
  [[nodiscard]] virtual ServedScene scene() const {
    ServedScene scene;
    scene.scene_hash = kHash;
    scene.serve_id = 1;
    scene.tool_count = 1;
    return scene;
  }

  void SetUp() override {
    ASSERT_TRUE(test::on_loopback_config());
    client.emplace(participant, options());
    client->set_scene(scene());
    const auto give_up = std::chrono::steady_clock::now() + std::chrono::seconds(10);
    while ((models_out.matched_readers() == 0 || states_in.matched_writers() == 0) &&
           std::chrono::steady_clock::now() < give_up) {
      std::this_thread::sleep_for(std::chrono::milliseconds(2));
    }
  }

  // One loop cycle at device position p (the loop's read, step and write, without the thread).
  const DeviceCommand& cycle(const Vec3& p_m) {
    input.p_world = p_m;
    return step_once();
  }

  // One loop cycle on `input` as it is.
  const DeviceCommand& step_once() {
    const DeviceCommand& command = client->step(input, 0.001);
    HapticCycle c;
    c.input = &input;
    c.output = &command;
    client->after_cycle(c);
    return command;
  }

  // The newest state the client published, as the simulation receives it.
  DeviceStateSample newest_state() {
    DeviceStateSample newest;
    for (int tries = 0; tries < 200 && newest.sequence == 0; ++tries) {
      states_in.take([&](const hapsim_msg_DeviceState& m, const dds_sample_info_t&) {
        newest = decode_device_state(m);
      });
      std::this_thread::sleep_for(std::chrono::milliseconds(1));
    }
    return newest;
  }

  // Milliseconds since `t`: a model older than the renderer's 100 ms is faded, so a test whose
  // thread stalled that long checks nothing.
  static double ms_since(std::chrono::steady_clock::time_point t) {
    return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t).count();
  }

  // A wall below z = 0 answering the state `answered`: the device at x0, pressing 2 N, 1000 N/m.
  LocalContactModel wall_model(std::uint64_t sequence, std::uint64_t answered, const Vec3& x0) {
    LocalContactModel m;
    m.x0_world_m = x0;
    m.f0_world_n = Vec3(0.0, 0.0, 2.0);
    m.stiffness_n_per_m = 1000.0 * Vec3::UnitZ() * Vec3::UnitZ().transpose();
    m.normal_world = Vec3::UnitZ();
    m.validity_radius_m = 0.01;
    m.sequence = sequence;
    m.device_sequence = answered;
    m.valid = true;
    return m;
  }

  // A session (DDS partition) per test: ctest runs the tests of this file side by side.
  Participant participant{
      kDomain,
      std::string("dhc-") + ::testing::UnitTest::GetInstance()->current_test_info()->name()};
  std::optional<DeviceHostClient> client;
  TopicWriter<hapsim_msg_LocalModel> models_out{participant};
  TopicReader<hapsim_msg_DeviceState> states_in{participant};
  DeviceInput input;
};

TEST_F(DeviceHostClientTest, RendersTheModelAtTheDevicesOwnPositionAndOnlyOurs) {
  const Vec3 x0(0.0, 0.0, -0.001);
  for (int k = 0; k < 5; ++k) {
    EXPECT_EQ(cycle(x0).force_world_n, Vec3::Zero());  // no model yet
  }
  const DeviceStateSample state = newest_state();
  ASSERT_GT(state.sequence, 0u);
  EXPECT_EQ(state.input.p_world, x0);

  // The simulation's own script: never rendered.
  models_out.write(encode_local_model(wall_model(1, 0, x0), {0, 0}, kHash));
  std::this_thread::sleep_for(std::chrono::milliseconds(20));
  for (int k = 0; k < 30; ++k) {
    EXPECT_EQ(cycle(x0).force_world_n, Vec3::Zero());
  }
  EXPECT_EQ(client->status().models_not_ours, 1u);

  // A model answering our state: blended in over 20 ms, then f0 + K·(x0 − x) where the device
  // is. The device has moved 1 mm further in since that state: 2 N + 1000 N/m × 1 mm = 3 N.
  models_out.write(encode_local_model(wall_model(2, state.sequence, x0), {0, 0}, kHash));
  const auto written = std::chrono::steady_clock::now();
  const Vec3 deeper = x0 - Vec3(0.0, 0.0, 0.001);
  Vec3 f = Vec3::Zero();
  // Past the 20 ms blend, and before the model goes stale (100 ms): a machine that stalled this
  // thread past that cannot show the hold.
  const auto since_ms = [&] {
    return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - written)
        .count();
  };
  while (since_ms() < 40.0) {
    f = cycle(deeper).force_world_n;
    std::this_thread::sleep_for(std::chrono::milliseconds(1));
  }
  f = cycle(deeper).force_world_n;
  if (since_ms() > 90.0) {
    GTEST_SKIP() << "this thread stalled for " << since_ms() << " ms: the model went stale";
  }
  EXPECT_NEAR(f.z(), 3.0, 1e-9);
  EXPECT_NEAR(f.head<2>().norm(), 0.0, 1e-12);
  const DeviceHostStatus s = client->status();
  EXPECT_EQ(s.models_accepted, 1u);
  EXPECT_GT(s.round_trip_us.count, 0u);
  EXPECT_NEAR(s.peak_force_n, 3.0, 1e-9);
}

TEST_F(DeviceHostClientTest, ACycleAllocatesNothing) {
  const Vec3 x0(0.0, 0.0, -0.001);
  for (int k = 0; k < 5; ++k) {
    (void)cycle(x0);
  }
  const DeviceStateSample state = newest_state();
  models_out.write(encode_local_model(wall_model(1, state.sequence, x0), {0, 0}, kHash));
  std::this_thread::sleep_for(std::chrono::milliseconds(20));
  for (int k = 0; k < 30; ++k) {  // blended in (20 ms of the host's clock)
    (void)cycle(x0);
    std::this_thread::sleep_for(std::chrono::milliseconds(1));
  }
  const long before = hapsim::test::thread_allocation_count();
  for (int k = 0; k < 500; ++k) {
    (void)cycle(x0 + Vec3(0.0, 0.0, -1e-6 * k));
  }
  EXPECT_EQ(hapsim::test::thread_allocation_count() - before, 0);
  EXPECT_GT(client->status().peak_force_n, 1.0);  // it rendered the model meanwhile
}

// A tool on a finger (a force glove's) renders to the finger actuator's rating, not the tip's,
// into that finger's slot of the command, and the simulation hears it there.
class GloveHostTest : public DeviceHostClientTest {
 protected:
  [[nodiscard]] DeviceHostOptions options() const override {
    DeviceHostOptions o;
    o.render.max_force_n = 8.0;  // a tip rating the finger must not get
    o.max_finger_force_n = 4.0;
    return o;
  }
  [[nodiscard]] ServedScene scene() const override {
    ServedScene s = DeviceHostClientTest::scene();
    s.tool_finger[0] = 1;
    return s;
  }
};

TEST_F(GloveHostTest, AFingerToolRendersIntoItsFingerAtTheFingersRating) {
  const Vec3 x0(0.0, 0.0, -0.001);
  for (int k = 0; k < 5; ++k) {
    (void)cycle(x0);
  }
  const DeviceStateSample state = newest_state();
  ASSERT_GT(state.sequence, 0u);
  // 6 mm deeper than the state answered: 2 N + 1000 N/m × 6 mm = 8 N, held to the finger's 4 N.
  const Vec3 deeper = x0 - Vec3(0.0, 0.0, 0.006);
  DeviceCommand command;
  std::uint64_t sent = 0;
  for (int k = 0; k < 60; ++k) {
    if (k % 10 == 0) {
      models_out.write(
          encode_local_model(wall_model(1 + sent++, state.sequence, x0), {0, 0}, kHash));
    }
    command = cycle(deeper);
    std::this_thread::sleep_for(std::chrono::milliseconds(1));
  }
  ASSERT_GE(client->status().models_accepted, 1u);
  EXPECT_NEAR(command.finger_force_n[1], 4.0, 1e-9);
  EXPECT_EQ(command.finger_force_n[0], 0.0);
  EXPECT_EQ(command.force_world_n, Vec3::Zero());  // nothing on the tip
  // What the simulation hears it rendered, finger by finger.
  const DeviceStateSample said = newest_state();
  EXPECT_NEAR(said.rendered.finger_force_n[1], 4.0, 1e-9);
}

// A master arm's reading: its three arm joints and both fingers at `finger_rad`.
DeviceInput master_reading(const std::array<double, 3>& arm_rad, double finger_rad) {
  DeviceInput in;
  in.healthy = true;
  in.joint_count = 3;
  in.finger_count = 2;
  for (std::size_t i = 0; i < 3; ++i) {
    in.joint_rad[i] = arm_rad[i];
  }
  in.finger_rad[0] = in.finger_rad[1] = finger_rad;
  return in;
}

// A rig's master arm (DeviceHostOptions::rig): its one tool is the tool the slave carries, placed
// where the slave's target puts it for the master's joints; the force rendered there reaches the
// master as the rig's own command makes it (RigController::master_command: Jᵀ), no tip force, and
// the state tells the simulation that force as the push its tissue takes.
class RigMasterHostTest : public DeviceHostClientTest {
 protected:
  [[nodiscard]] DeviceHostOptions options() const override {
    DeviceHostOptions o;
    o.rig = rig;
    o.rig_tool_flange_m = kToolInFlange;
    return o;
  }

  static std::shared_ptr<const RigController> make_rig() {
    TeleopRigDescription d;
    d.slave = std::make_shared<const SerialChain>(make_procedural_motoman());
    return std::make_shared<const RigController>(std::move(d));
  }

  static DeviceInput master(const std::array<double, 3>& arm_rad) {
    return master_reading(arm_rad, 0.0);
  }

  const DeviceCommand& master_cycle(const std::array<double, 3>& arm_rad) {
    input = master(arm_rad);
    return step_once();
  }

  inline static const Vec3 kToolInFlange{0.0, 0.0, 0.1};
  std::shared_ptr<const RigController> rig = make_rig();
};

TEST_F(RigMasterHostTest, TheCarriedToolsForceIsFeltThroughTheMastersJacobian) {
  const std::array<double, 3> at_state{0.1, 0.7, 1.4};
  for (int k = 0; k < 5; ++k) {
    EXPECT_EQ(master_cycle(at_state).joint_torque_nm[1], 0.0);  // no model yet
  }
  const DeviceStateSample state = newest_state();
  ASSERT_GT(state.sequence, 0u);
  // The model answers that state with the tool where the slave's target put it then; the master
  // has since moved its elbow a little, and the tool with it.
  const Vec3 x0 = rig->flange_point_target_world(master(at_state), kToolInFlange);
  ASSERT_TRUE(x0.allFinite());
  const std::array<double, 3> now{0.1, 0.7, 1.4005};
  const Vec3 x = rig->flange_point_target_world(master(now), kToolInFlange);
  ASSERT_GT((x - x0).norm(), 1e-5);
  ASSERT_LT((x - x0).norm(), 2e-3);
  // f0 + K·(x0 − x), K along z: the wall model's 2 N and 1000 N/m.
  const Vec3 expected_n(0.0, 0.0, 2.0 + 1000.0 * (x0.z() - x.z()));
  DeviceCommand command;
  std::uint64_t sent = 0;
  auto last_written = std::chrono::steady_clock::now();
  // Models for 30 ms, then 30 more cycles: each adoption restarts the 20 ms blend from the force
  // before it, and the newest (not stale before 100 ms) is rendered as it is once that is done.
  for (int k = 0; k < 60; ++k) {
    if (k % 10 == 0 && k < 30) {
      models_out.write(
          encode_local_model(wall_model(1 + sent++, state.sequence, x0), {0, 0}, kHash));
      last_written = std::chrono::steady_clock::now();
    }
    command = master_cycle(now);
    std::this_thread::sleep_for(std::chrono::milliseconds(1));
  }
  ASSERT_GE(client->status().models_accepted, 1u);
  if (const double since_ms = ms_since(last_written); since_ms > 90.0) {
    GTEST_SKIP() << "this thread stalled: the last model is " << since_ms << " ms old (stale)";
  }
  DeviceCommand want;
  rig->master_command(now, expected_n, 0.0, want);
  EXPECT_EQ(command.joint_count, 5);
  for (std::size_t i = 0; i < 3; ++i) {
    EXPECT_NEAR(command.joint_torque_nm[i], want.joint_torque_nm[i], 1e-9) << i;
  }
  EXPECT_GT(std::abs(want.joint_torque_nm[1]) + std::abs(want.joint_torque_nm[2]), 0.1);
  EXPECT_EQ(command.force_world_n, Vec3::Zero());  // a master has no tip
  EXPECT_NEAR(client->status().force_n, expected_n.norm(), 1e-9);
  EXPECT_GT(client->status().peak_joint_torque_nm, 0.1);
  // The simulation hears the force the torques stand for: its tissue gives way to it (SPEC §8).
  DeviceStateSample newest;
  for (int tries = 0; tries < 200 && newest.sequence < state.sequence + 60; ++tries) {
    states_in.take([&](const hapsim_msg_DeviceState& m, const dds_sample_info_t&) {
      newest = decode_device_state(m);
    });
    std::this_thread::sleep_for(std::chrono::milliseconds(1));
  }
  EXPECT_TRUE(newest.rendered.force_world_n.isApprox(expected_n, 1e-9))
      << newest.rendered.force_world_n.transpose();
}

// The master's cycle on the haptic path: where the slave's target puts the tool, the rendered
// model, the master's Jᵀ and the state it sends allocate nothing, as the probe's cycle does.
TEST_F(RigMasterHostTest, AMasterCycleAllocatesNothing) {
  const std::array<double, 3> at_state{0.1, 0.7, 1.4};
  for (int k = 0; k < 5; ++k) {
    (void)master_cycle(at_state);
  }
  const DeviceStateSample state = newest_state();
  const Vec3 x0 = rig->flange_point_target_world(master(at_state), kToolInFlange);
  models_out.write(encode_local_model(wall_model(1, state.sequence, x0), {0, 0}, kHash));
  std::this_thread::sleep_for(std::chrono::milliseconds(20));
  for (int k = 0; k < 30; ++k) {  // blended in (20 ms of the host's clock)
    (void)master_cycle(at_state);
    std::this_thread::sleep_for(std::chrono::milliseconds(1));
  }
  const long before = hapsim::test::thread_allocation_count();
  for (int k = 0; k < 500; ++k) {
    (void)master_cycle({0.1, 0.7, 1.4 + 1e-6 * k});
  }
  EXPECT_EQ(hapsim::test::thread_allocation_count() - before, 0);
  EXPECT_GT(client->status().peak_joint_torque_nm, 0.1);  // it rendered the model meanwhile
}

// A rig that grasps a ball: the served world sends its two pads' models (rig/pad_models.h) in the
// grip's frame after the master's tools (here none), and the master feels their push on its
// fingers and their sum (what the ball weighs on them) through its arm's Jᵀ. Carrying the grip
// squeezes nothing; opening it lets the pads off the ball by the pads' spring.
class RigGraspHostTest : public DeviceHostClientTest {
 protected:
  [[nodiscard]] DeviceHostOptions options() const override {
    DeviceHostOptions o;
    o.rig = rig;
    o.render.max_force_n = 100.0;  // the simulated master's rating: the 2 x 20 N are not clamped
    // The models start preloaded (the grip this host never saw close), so letting it off gives
    // back energy the observer never saw go in: it would damp the opening checked below.
    o.passivity.enabled = false;
    return o;
  }
  [[nodiscard]] ServedScene scene() const override {
    ServedScene s = DeviceHostClientTest::scene();
    s.tool_count = 0;  // the pick-and-place rig carries no tool: only its pads are served
    return s;
  }

  static std::shared_ptr<const RigController> make_rig() {
    TeleopRigDescription d;
    d.slave = std::make_shared<const SerialChain>(make_procedural_motoman());
    d.ball_body = 0;  // the host never reads the bodies: only that there are a ball and pads
    d.pad_body = {1, 2};
    return std::make_shared<const RigController>(std::move(d));
  }

  static DeviceInput master(const std::array<double, 3>& arm_rad, double finger_rad) {
    return master_reading(arm_rad, finger_rad);
  }

  // Pad `i`'s model for the pads where the master `in` puts them: in the grip's frame (from the
  // pads' midpoint), pushing `push_n` out of the ball and carrying half the ball's 1 N weight.
  LocalContactModel pad_model(const DeviceInput& in, std::size_t i, double push_n,
                              std::uint64_t sequence, std::uint64_t answered) const {
    const Vec3 p0 = rig->pad_centre_target_world(in, 0);
    const Vec3 p1 = rig->pad_centre_target_world(in, 1);
    const Vec3 x0 = i == 0 ? Vec3(0.5 * (p0 - p1)) : Vec3(0.5 * (p1 - p0));
    const Vec3 n = x0.normalized();
    LocalContactModel m;
    m.x0_world_m = x0;
    m.f0_world_n = push_n * n + Vec3(0.0, 0.0, -0.5);
    m.stiffness_n_per_m = kPadStiffness * n * n.transpose();
    m.normal_world = n;
    m.validity_radius_m = 0.01;
    m.max_normal_force_n = 20.0;
    m.sequence = sequence;
    m.device_sequence = answered;
    m.valid = true;
    return m;
  }

  static constexpr double kPadStiffness = 5000.0;
  std::shared_ptr<const RigController> rig = make_rig();
};

TEST_F(RigGraspHostTest, TheMasterFeelsTheGripAndTheBallsWeight) {
  const std::array<double, 3> at_state{0.1, 0.7, 1.4};
  constexpr double kFinger = 0.3;
  for (int k = 0; k < 5; ++k) {
    input = master(at_state, kFinger);
    EXPECT_EQ(step_once().finger_force_n[0], 0.0);  // no model yet
  }
  const DeviceStateSample state = newest_state();
  ASSERT_GT(state.sequence, 0u);
  const DeviceInput there = master(at_state, kFinger);
  ASSERT_TRUE(rig->pad_centre_target_world(there, 0).allFinite());
  // Since that state the master carried the grip 2 mrad of shoulder on (millimetres in the world).
  const std::array<double, 3> carried{0.1, 0.702, 1.4};
  ASSERT_GT((rig->pad_centre_target_world(master(carried, kFinger), 0) -
             rig->pad_centre_target_world(there, 0))
                .norm(),
            5e-4);
  std::uint64_t sent = 0;
  auto last_written = std::chrono::steady_clock::now();
  DeviceCommand command;
  for (int k = 0; k < 60; ++k) {  // models for 30 ms, then the blend runs out
    if (k % 10 == 0 && k < 30) {
      ++sent;
      for (std::size_t i = 0; i < 2; ++i) {
        models_out.write(encode_local_model(pad_model(there, i, 15.0, sent, state.sequence),
                                            {0, static_cast<std::uint16_t>(i)}, kHash));
      }
      last_written = std::chrono::steady_clock::now();
    }
    input = master(carried, kFinger);
    command = step_once();
    std::this_thread::sleep_for(std::chrono::milliseconds(1));
  }
  ASSERT_GE(client->status().models_accepted, 2u);
  if (const double since_ms = ms_since(last_written); since_ms > 90.0) {
    GTEST_SKIP() << "this thread stalled: the last model is " << since_ms << " ms old (stale)";
  }
  // Carried, not squeezed: the grip is the models' 15 N, the pads' sum the ball's weight.
  EXPECT_NEAR(command.finger_force_n[0], 15.0, 1e-9);
  EXPECT_NEAR(command.finger_force_n[1], 15.0, 1e-9);
  DeviceCommand want;
  rig->master_command(carried, Vec3(0.0, 0.0, -1.0), 15.0, want);
  for (std::size_t j = 0; j < 5; ++j) {
    EXPECT_NEAR(command.joint_torque_nm[j], want.joint_torque_nm[j], 1e-9) << j;
  }
  EXPECT_GT(std::abs(want.joint_torque_nm[1]) + std::abs(want.joint_torque_nm[2]), 0.01);
  EXPECT_EQ(command.force_world_n, Vec3::Zero());
  // Opening the grip lets each pad off by how far it moved out along its normal.
  const DeviceInput opened = master(carried, kFinger + 0.005);
  const Vec3 x_before = rig->pad_centre_target_world(master(carried, kFinger), 0) -
                        rig->pad_centre_target_world(master(carried, kFinger), 1);
  const Vec3 x_after =
      rig->pad_centre_target_world(opened, 0) - rig->pad_centre_target_world(opened, 1);
  const double out_m = 0.5 * (x_after.norm() - x_before.norm());
  ASSERT_GT(out_m, 1e-5);
  ASSERT_LT(kPadStiffness * out_m, 2.0);  // within a cycle's rate limit
  input = opened;
  command = step_once();
  EXPECT_NEAR(command.finger_force_n[0], 15.0 - kPadStiffness * out_m, 1e-6);
  const DeviceHostStatus status = client->status();
  EXPECT_NEAR(status.peak_grasp_force_n, 15.0, 1e-9);
  EXPECT_GT(status.held_cycles, 10u);
  EXPECT_NEAR(status.mean_held_force_n, 1.0, 0.5);  // the weight, after the blend from nothing
}

// Two device hosts on one device id (a second `hapsim device --name trainee`): each numbers its
// states from its own random base, so the models answering the first host's states are the
// second's "another host's", refused and counted, never rendered; the first renders them.
TEST_F(DeviceHostClientTest, ASecondHostOnTheSameDeviceIdTellsTheOthersModelsFromItsOwn) {
  DeviceHostClient second(participant, options());
  second.set_scene(scene());
  const Vec3 x0(0.0, 0.0, -0.001);
  DeviceInput second_input;
  second_input.p_world = x0;
  for (int k = 0; k < 5; ++k) {
    (void)cycle(x0);
    (void)second.step(second_input, 0.001);
  }
  const DeviceStateSample state = newest_state();  // the first host's
  ASSERT_GT(state.sequence, 0u);
  models_out.write(encode_local_model(wall_model(1, state.sequence, x0), {0, 0}, kHash));
  std::this_thread::sleep_for(std::chrono::milliseconds(20));
  for (int k = 0; k < 30; ++k) {
    (void)cycle(x0);
    EXPECT_EQ(second.step(second_input, 0.001).force_world_n, Vec3::Zero());
  }
  EXPECT_EQ(client->status().models_accepted, 1u);
  EXPECT_EQ(client->status().models_other_device_host, 0u);
  const DeviceHostStatus s = second.status();
  EXPECT_EQ(s.models_accepted, 0u);
  EXPECT_EQ(s.models_other_device_host, 1u);
  EXPECT_EQ(s.verdicts[static_cast<std::size_t>(SampleVerdict::kOtherHost)], 1u);
}

// A host's states are numbered from its own base (given here; random by default): the first
// state is base + 1.
TEST_F(DeviceHostClientTest, StatesAreNumberedFromTheHostsOwnBase) {
  DeviceHostOptions o = options();
  o.state_sequence_base = 1'000'000;
  client.emplace(participant, o);
  client->set_scene(scene());
  (void)cycle(Vec3::Zero());
  const DeviceStateSample state = newest_state();
  EXPECT_EQ(state.sequence, 1'000'001u);
}

}  // namespace
}  // namespace hapsim::net
