// The simulation host's device (net/remote_device.h) against a device host played by the test
// over DDS on loopback: a second writer on the same device id steers nothing while the first
// drives (a name already taken), and the first real state after a dead-reckoned cycle is stamped
// at least a step after it, so the estimate's correction never reads as a fast motion.
#include "hapsim/net/remote_device.h"
#include "hapsim/device/absent_device.h"
#include "hapsim/net/device_state_codec.h"
#include "hapsim/net/topic_writer.h"

#include "net/net_test_support.h"

#include <chrono>
#include <string>
#include <thread>

#include <gtest/gtest.h>

namespace hapsim::net {
namespace {

constexpr dds_domainid_t kDomain = 89;
constexpr std::uint64_t kHash = 0xabcdULL;

class RemoteDeviceTest : public ::testing::Test {
 protected:
  void SetUp() override { ASSERT_TRUE(test::on_loopback_config()); }

  // Waits until `writer` reaches the device's reader.
  static void matched(const TopicWriter<hapsim_msg_DeviceState>& writer) {
    const auto give_up = std::chrono::steady_clock::now() + std::chrono::seconds(10);
    while (writer.matched_readers() == 0 && std::chrono::steady_clock::now() < give_up) {
      std::this_thread::sleep_for(std::chrono::milliseconds(2));
    }
  }
  // A host state: sequence `n` stamped `host_time_s` at x = `x_m`, moving at `v_m_per_s` along x.
  static hapsim_msg_DeviceState state(std::uint64_t n, double host_time_s, double x_m,
                                      double v_m_per_s = 0.0) {
    DeviceStateSample s;
    s.sequence = n;
    s.input.time_s = host_time_s;
    s.input.p_world = Vec3(x_m, 0.0, 0.0);
    s.v_world_m_per_s = Vec3(v_m_per_s, 0.0, 0.0);
    return encode_device_state(s, kHash);
  }
  static void settle() { std::this_thread::sleep_for(std::chrono::milliseconds(30)); }

  Participant participant{
      kDomain,
      std::string("rd-") + ::testing::UnitTest::GetInstance()->current_test_info()->name()};
  AbsentDevice fallback{DeviceProfile{}};
  // A long host timeout: the test's sleeps must not read as a silent host.
  RemoteDevice remote{participant, 0, kHash, fallback, 5.0};
};

TEST_F(RemoteDeviceTest, ASecondHostOnTheSameIdSteersNothingWhileTheFirstDrives) {
  TopicWriter<hapsim_msg_DeviceState> first(participant);
  TopicWriter<hapsim_msg_DeviceState> second(participant);
  matched(first);
  matched(second);
  ASSERT_TRUE(first.write(state(100, 1.0, 0.01)));
  settle();
  EXPECT_NEAR(remote.read(0.0).p_world.x(), 0.01, 1e-15);
  ASSERT_TRUE(remote.take_source_switch());
  ASSERT_TRUE(second.write(state(900, 1.001, 0.05)));  // newer, but another host's
  settle();
  EXPECT_NEAR(remote.read(0.001).p_world.x(), 0.01, 1e-15);  // held (no velocity to reckon)
  EXPECT_EQ(remote.other_host_states(), 1u);
  EXPECT_EQ(remote.verdicts()[static_cast<std::size_t>(SampleVerdict::kOtherHost)], 1u);
  ASSERT_TRUE(first.write(state(101, 1.001, 0.011)));
  settle();
  EXPECT_NEAR(remote.read(0.002).p_world.x(), 0.011, 1e-15);
}

TEST_F(RemoteDeviceTest, TheFirstStateAfterAReckonedCycleIsAtLeastAStepLater) {
  TopicWriter<hapsim_msg_DeviceState> host(participant);
  matched(host);
  // 0.1 m/s along x, one state a millisecond; the third is late (the host's own cycle ran 0.1 ms
  // late and serve stepped without it, reckoning the device at 0.2 mm), and the device had in
  // fact gone on to 0.25 mm.
  ASSERT_TRUE(host.write(state(1, 5.000, 0.0000, 0.1)));
  settle();
  const DeviceInput a = remote.read(0.000);
  ASSERT_TRUE(a.healthy);
  ASSERT_TRUE(remote.take_source_switch());  // the host joined (serve restarts the tools)
  ASSERT_TRUE(host.write(state(2, 5.001, 0.0001, 0.1)));
  settle();
  const DeviceInput b = remote.read(0.001);
  EXPECT_NEAR(b.time_s - a.time_s, 0.001, 1e-12);
  const DeviceInput reckoned = remote.read(0.002);  // no state: moved on at 0.1 m/s
  EXPECT_NEAR(reckoned.p_world.x(), 0.0002, 1e-12);
  EXPECT_NEAR(reckoned.time_s - b.time_s, 0.001, 1e-12);
  ASSERT_TRUE(host.write(state(3, 5.0021, 0.00025, 0.05)));
  settle();
  const DeviceInput late = remote.read(0.003);
  EXPECT_NEAR(late.p_world.x(), 0.00025, 1e-15);
  // Over its own 0.1 ms the correction (0.05 mm) would read as 0.5 m/s, five times the device's
  // speed; over a step, 0.05 m/s.
  const double elapsed_s = late.time_s - reckoned.time_s;
  EXPECT_NEAR(elapsed_s, 0.001, 1e-12);
  // Later states keep their own differences, from the shifted anchor.
  ASSERT_TRUE(host.write(state(4, 5.0031, 0.0003, 0.05)));
  settle();
  EXPECT_NEAR(remote.read(0.004).time_s - late.time_s, 0.001, 1e-12);
}

// A master arm's joints (and fingers) move on at the rate of its last two states in a cycle
// without one, as the tip does at its velocity: held, the served slave would stand a cycle and
// then jump two, and a ball its pads hold would take that stop's deceleration.
TEST_F(RemoteDeviceTest, AMastersJointsMoveOnAtTheirRateInACycleWithoutAState) {
  TopicWriter<hapsim_msg_DeviceState> host(participant);
  matched(host);
  const auto master_state = [](std::uint64_t n, double host_time_s, double shoulder_rad,
                               double finger_rad) {
    DeviceStateSample s;
    s.sequence = n;
    s.input.time_s = host_time_s;
    s.input.joint_count = 3;
    s.input.joint_rad = {0.1, shoulder_rad, 1.4};
    s.input.finger_count = 2;
    s.input.finger_rad = {finger_rad, finger_rad};
    return encode_device_state(s, kHash);
  };
  // The shoulder at 2 rad/s, the fingers closing at 1 rad/s.
  ASSERT_TRUE(host.write(master_state(1, 5.000, 0.700, 0.300)));
  settle();
  (void)remote.read(0.000);
  ASSERT_TRUE(host.write(master_state(2, 5.001, 0.702, 0.299)));
  settle();
  const DeviceInput b = remote.read(0.001);
  EXPECT_NEAR(b.joint_rad[1], 0.702, 1e-15);
  const DeviceInput reckoned = remote.read(0.002);  // no state
  EXPECT_NEAR(reckoned.joint_rad[1], 0.704, 1e-12);
  EXPECT_NEAR(reckoned.joint_rad[0], 0.1, 1e-15);  // standing joints stand
  EXPECT_NEAR(reckoned.finger_rad[0], 0.298, 1e-12);
  EXPECT_NEAR(reckoned.finger_rad[1], 0.298, 1e-12);
  const DeviceInput twice = remote.read(0.003);  // still none
  EXPECT_NEAR(twice.joint_rad[1], 0.706, 1e-12);
  // The real state takes over where it says the master is.
  ASSERT_TRUE(host.write(master_state(3, 5.004, 0.7075, 0.296)));
  settle();
  EXPECT_NEAR(remote.read(0.004).joint_rad[1], 0.7075, 1e-15);
}

// Several users: the other users' states reach every link in serve; each link skips its
// siblings' without a verdict, so "other device" counts only strangers' states.
TEST_F(RemoteDeviceTest, AnotherUsersStatesAreNotCountedAsAStrangersDevice) {
  const std::uint16_t sibling = 1;
  remote.set_sibling_device_ids({&sibling, 1});
  TopicWriter<hapsim_msg_DeviceState> other_user(participant);
  matched(other_user);
  hapsim_msg_DeviceState from_sibling = state(1, 1.0, 0.02);
  from_sibling.device_id = 1;
  hapsim_msg_DeviceState from_stranger = state(1, 1.0, 0.03);
  from_stranger.device_id = 7;
  ASSERT_TRUE(other_user.write(from_sibling));
  ASSERT_TRUE(other_user.write(from_stranger));
  settle();
  EXPECT_FALSE(remote.read(0.0).healthy);  // neither drives this device (its fallback: absent)
  const VerdictCounts v = remote.verdicts();
  EXPECT_EQ(v[static_cast<std::size_t>(SampleVerdict::kOtherDevice)], 1u);  // the stranger only
  EXPECT_EQ(v[static_cast<std::size_t>(SampleVerdict::kAccepted)], 0u);
}

}  // namespace
}  // namespace hapsim::net
