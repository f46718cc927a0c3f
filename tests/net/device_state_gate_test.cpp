#include "hapsim/net/device_state_gate.h"

#include <limits>

#include <gtest/gtest.h>

namespace hapsim::net {
namespace {

constexpr std::uint64_t kHash = 0xabcdef;

hapsim_msg_DeviceState state(std::uint64_t sequence) {
  DeviceStateSample s;
  s.device_id = 2;
  s.sequence = sequence;
  s.input.time_s = 0.5;
  s.input.p_world = Vec3(0.1, 0.2, 0.3);
  s.input.q_world = Quat(Eigen::AngleAxisd(0.3, Vec3::UnitZ()));
  s.input.finger_count = 2;
  s.input.finger_rad = {0.1, 0.2, 0.0, 0.0, 0.0};
  s.input.joint_count = 3;  // a master arm's base, shoulder and elbow
  s.input.joint_rad[0] = 0.4;
  s.input.joint_rad[2] = -1.1;
  s.input.buttons = 5;
  s.v_world_m_per_s = Vec3(0.01, 0.0, -0.02);
  s.rendered.force_world_n = Vec3(0.0, 0.0, 1.5);
  return encode_device_state(s, kHash);
}

TEST(DeviceStateCodec, RoundTripsTheInputAndTheRenderedForce) {
  const DeviceStateSample s = decode_device_state(state(9));
  EXPECT_EQ(s.device_id, 2);
  EXPECT_EQ(s.sequence, 9u);
  EXPECT_EQ(s.input.p_world, Vec3(0.1, 0.2, 0.3));
  EXPECT_TRUE(s.input.q_world.isApprox(Quat(Eigen::AngleAxisd(0.3, Vec3::UnitZ()))));
  EXPECT_EQ(s.input.finger_count, 2);
  EXPECT_EQ(s.input.finger_rad[1], 0.2);
  EXPECT_EQ(s.input.joint_count, 3);
  EXPECT_EQ(s.input.joint_rad[0], 0.4);
  EXPECT_EQ(s.input.joint_rad[2], -1.1);
  EXPECT_EQ(s.input.buttons, 5u);
  EXPECT_EQ(s.rendered.force_world_n.z(), 1.5);
  EXPECT_EQ(s.v_world_m_per_s, Vec3(0.01, 0.0, -0.02));
}

TEST(DeviceStateGate, CountsEachReasonAndAppliesOnlyGoodStates) {
  DeviceStateGate gate(2, kHash);
  DeviceStateSample out;
  EXPECT_EQ(gate.admit(state(5), out), SampleVerdict::kAccepted);
  hapsim_msg_DeviceState nan_pose = state(6);
  nan_pose.p_m[0] = std::numeric_limits<double>::quiet_NaN();
  hapsim_msg_DeviceState too_many_fingers = state(6);
  too_many_fingers.finger_count = 9;
  hapsim_msg_DeviceState too_many_joints = state(6);
  too_many_joints.joint_count = 17;
  hapsim_msg_DeviceState nan_joint = state(6);
  nan_joint.joint_rad[1] = std::numeric_limits<double>::infinity();
  hapsim_msg_DeviceState not_unit = state(6);
  not_unit.q_wxyz[0] = 3.0;
  hapsim_msg_DeviceState far = state(6);
  far.p_m[2] = 1e4;
  hapsim_msg_DeviceState other_scene = state(6);
  other_scene.scene_hash = 1;
  hapsim_msg_DeviceState other_device = state(6);
  other_device.device_id = 3;
  EXPECT_EQ(gate.admit(nan_pose, out), SampleVerdict::kMalformed);
  EXPECT_EQ(gate.admit(too_many_fingers, out), SampleVerdict::kMalformed);
  EXPECT_EQ(gate.admit(too_many_joints, out), SampleVerdict::kMalformed);
  EXPECT_EQ(gate.admit(nan_joint, out), SampleVerdict::kMalformed);
  EXPECT_EQ(gate.admit(not_unit, out), SampleVerdict::kOutOfRange);
  EXPECT_EQ(gate.admit(far, out), SampleVerdict::kOutOfRange);
  EXPECT_EQ(gate.admit(other_scene, out), SampleVerdict::kOtherScene);
  EXPECT_EQ(gate.admit(other_device, out), SampleVerdict::kOtherDevice);
  EXPECT_EQ(gate.admit(state(5), out), SampleVerdict::kOutOfOrder);
  EXPECT_EQ(out.sequence, 5u);  // nothing rejected was applied
  EXPECT_EQ(gate.admit(state(6), out), SampleVerdict::kAccepted);
  EXPECT_EQ(gate.count(SampleVerdict::kMalformed), 4u);
  EXPECT_EQ(gate.count(SampleVerdict::kOutOfRange), 2u);
  EXPECT_EQ(gate.count(SampleVerdict::kOtherScene), 1u);
  EXPECT_EQ(gate.count(SampleVerdict::kOtherDevice), 1u);
  EXPECT_EQ(gate.count(SampleVerdict::kOutOfOrder), 1u);
  EXPECT_EQ(gate.count(SampleVerdict::kAccepted), 2u);
}

}  // namespace
}  // namespace hapsim::net
