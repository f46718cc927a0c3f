#include "hapsim/net/local_model_gate.h"

#include "net/net_test_support.h"
#include "support/allocation_counter.h"

#include <array>
#include <cmath>
#include <limits>

#include <gtest/gtest.h>

namespace hapsim::net {
namespace {

using test::kDeviceId;
using test::kSceneHash;
using test::message_for;

constexpr std::uint64_t kNow = 100;

TEST(LocalModelCodec, RoundTripsEveryFieldBitForBit) {
  const hapsim_msg_LocalModel m = message_for(42);
  const hapsim_msg_LocalModel again =
      encode_local_model(decode_local_model(m), {kDeviceId, 0}, kSceneHash);
  EXPECT_TRUE(test::same_bits(m, again));
  EXPECT_EQ(decode_local_model(m).stiffness_n_per_m(0, 2), 2.0);  // row-major
  // No cap travels as -1 and comes back as none; a cap as itself.
  EXPECT_EQ(m.max_normal_force_n, -1.0);
  EXPECT_TRUE(std::isinf(decode_local_model(m).max_normal_force_n));
  LocalContactModel capped = test::model_for(43);
  capped.max_normal_force_n = 9.2;
  EXPECT_EQ(
      decode_local_model(encode_local_model(capped, {kDeviceId, 0}, kSceneHash)).max_normal_force_n,
      9.2);
  // A profile travels point by point.
  LocalContactModel stiffening = test::model_for(44);
  stiffening.profile_count = 3;
  stiffening.profile_depth_m = {-0.002, 0.0, 0.004};
  stiffening.profile_push_n = {0.0, 1.0, 5.0};
  const hapsim_msg_LocalModel with_profile =
      encode_local_model(stiffening, {kDeviceId, 0}, kSceneHash);
  EXPECT_EQ(with_profile.profile_count, 3);
  EXPECT_TRUE(test::same_bits(with_profile, encode_local_model(decode_local_model(with_profile),
                                                               {kDeviceId, 0}, kSceneHash)));
  EXPECT_EQ(decode_local_model(with_profile).profile_push_n[2], 5.0);
}

// A profile must be a spring that pushes no less the deeper it goes, with at least two points.
TEST(LocalModelGate, RefusesAProfileThatIsNotAConservativeSpring) {
  const auto with_profile = [](std::uint64_t sequence, std::uint16_t count,
                               std::array<double, 3> depth_m, std::array<double, 3> push_n) {
    hapsim_msg_LocalModel m = message_for(sequence);
    m.profile_count = count;
    for (std::size_t i = 0; i < 3; ++i) {
      m.profile_depth_m[i] = depth_m[i];
      m.profile_push_n[i] = push_n[i];
    }
    return m;
  };
  LocalModelGate gate(kDeviceId, kSceneHash, 1);
  LocalContactModel out;
  const double nan = std::numeric_limits<double>::quiet_NaN();
  EXPECT_EQ(gate.admit(with_profile(10, 1, {0.0, 0.0, 0.0}, {1.0, 0.0, 0.0}), kNow, out),
            SampleVerdict::kMalformed);  // one point is no profile
  EXPECT_EQ(gate.admit(with_profile(10, 9, {0.0, 0.001, 0.002}, {1.0, 2.0, 3.0}), kNow, out),
            SampleVerdict::kMalformed);  // more than the wire holds
  EXPECT_EQ(gate.admit(with_profile(10, 3, {0.0, nan, 0.002}, {1.0, 2.0, 3.0}), kNow, out),
            SampleVerdict::kMalformed);
  EXPECT_EQ(gate.admit(with_profile(10, 3, {0.0, 0.001, 0.002}, {1.0, 0.5, 3.0}), kNow, out),
            SampleVerdict::kOutOfRange);  // pushes less deeper in: energy out
  EXPECT_EQ(gate.admit(with_profile(10, 3, {0.0, 0.002, 0.002}, {1.0, 2.0, 3.0}), kNow, out),
            SampleVerdict::kOutOfRange);  // two pushes at one depth
  EXPECT_EQ(gate.admit(with_profile(10, 3, {0.0, 0.001, 0.002}, {1.0, 2.0, 1e6}), kNow, out),
            SampleVerdict::kOutOfRange);
  EXPECT_EQ(gate.admit(with_profile(10, 3, {-0.002, 0.0, 0.004}, {0.0, 1.0, 5.0}), kNow, out),
            SampleVerdict::kAccepted);
  EXPECT_EQ(out.profile_count, 3);
}

TEST(LocalModelGate, AcceptsInOrderAndCountsEachReason) {
  LocalModelGate gate(kDeviceId, kSceneHash, 1);
  LocalContactModel out;
  EXPECT_EQ(gate.admit(message_for(10), kNow, out), SampleVerdict::kAccepted);
  EXPECT_EQ(out.sequence, 10u);

  hapsim_msg_LocalModel nan_force = message_for(11);
  nan_force.f0_n[1] = std::numeric_limits<double>::quiet_NaN();
  hapsim_msg_LocalModel inf_k = message_for(11);
  inf_k.stiffness_n_per_m[4] = std::numeric_limits<double>::infinity();
  hapsim_msg_LocalModel bad_finger = message_for(11);
  bad_finger.finger = 1;  // the device has one
  hapsim_msg_LocalModel huge_force = message_for(11);
  huge_force.f0_n[2] = 1e6;
  hapsim_msg_LocalModel negative_k = message_for(11);
  negative_k.stiffness_n_per_m[0] = -1.0;
  hapsim_msg_LocalModel long_normal = message_for(11);
  long_normal.normal[2] = 2.0;
  hapsim_msg_LocalModel nan_cap = message_for(11);
  nan_cap.max_normal_force_n = std::numeric_limits<double>::quiet_NaN();
  hapsim_msg_LocalModel negative_cap = message_for(11);
  negative_cap.max_normal_force_n = -2.0;  // -1 is "none"; any other negative is nonsense
  hapsim_msg_LocalModel future = message_for(11);
  future.device_sequence = kNow + 1;
  hapsim_msg_LocalModel other_scene = message_for(11);
  other_scene.scene_hash ^= 1u;
  hapsim_msg_LocalModel other_device = message_for(11);
  other_device.device_id = kDeviceId + 1;
  hapsim_msg_LocalModel stale = message_for(11);
  // answers device state 11: stale once the device is 500 cycles past it

  LocalContactModel untouched = out;
  EXPECT_EQ(gate.admit(nan_force, kNow, out), SampleVerdict::kMalformed);
  EXPECT_EQ(gate.admit(inf_k, kNow, out), SampleVerdict::kMalformed);
  EXPECT_EQ(gate.admit(bad_finger, kNow, out), SampleVerdict::kMalformed);
  EXPECT_EQ(gate.admit(nan_cap, kNow, out), SampleVerdict::kMalformed);
  EXPECT_EQ(gate.admit(negative_cap, kNow, out), SampleVerdict::kOutOfRange);
  EXPECT_EQ(gate.admit(huge_force, kNow, out), SampleVerdict::kOutOfRange);
  EXPECT_EQ(gate.admit(negative_k, kNow, out), SampleVerdict::kOutOfRange);
  EXPECT_EQ(gate.admit(long_normal, kNow, out), SampleVerdict::kOutOfRange);
  EXPECT_EQ(gate.admit(future, kNow, out), SampleVerdict::kOutOfRange);
  EXPECT_EQ(gate.admit(other_scene, kNow, out), SampleVerdict::kOtherScene);
  EXPECT_EQ(gate.admit(other_device, kNow, out), SampleVerdict::kOtherDevice);
  EXPECT_EQ(gate.admit(message_for(10), kNow, out), SampleVerdict::kOutOfOrder);  // duplicate
  EXPECT_EQ(gate.admit(message_for(9), kNow, out), SampleVerdict::kOutOfOrder);   // late
  EXPECT_EQ(gate.admit(stale, 11 + 501, out), SampleVerdict::kStale);
  // Nothing rejected reached the output.
  EXPECT_EQ(out.sequence, untouched.sequence);
  EXPECT_EQ(out.f0_world_n, untouched.f0_world_n);

  EXPECT_EQ(gate.admit(message_for(11), kNow, out), SampleVerdict::kAccepted);
  EXPECT_EQ(gate.count(SampleVerdict::kAccepted), 2u);
  EXPECT_EQ(gate.count(SampleVerdict::kMalformed), 4u);
  EXPECT_EQ(gate.count(SampleVerdict::kOutOfRange), 5u);
  EXPECT_EQ(gate.count(SampleVerdict::kOtherScene), 1u);
  EXPECT_EQ(gate.count(SampleVerdict::kOtherDevice), 1u);
  EXPECT_EQ(gate.count(SampleVerdict::kOutOfOrder), 2u);
  EXPECT_EQ(gate.count(SampleVerdict::kStale), 1u);
  EXPECT_EQ(gate.rejected(), 14u);
  EXPECT_STREQ(verdict_name(SampleVerdict::kStale), "stale");
}

// A model answering no device state (device sequence 0: the simulation's own script) has no age:
// it is not stale however far the device's count is (a device host numbers its states from a
// random base), so the host sees it for what it is, not its own, and renders nothing of it.
TEST(LocalModelGate, AModelAnsweringTheScriptIsNeverStale) {
  LocalModelGate gate(kDeviceId, kSceneHash, 1);
  LocalContactModel out;
  hapsim_msg_LocalModel script = message_for(1);
  script.device_sequence = 0;
  EXPECT_EQ(gate.admit(script, std::uint64_t{1} << 61, out), SampleVerdict::kAccepted);
  EXPECT_EQ(out.device_sequence, 0u);
}

TEST(LocalModelGate, AdmittingAndCodingAllocateNothing) {
  LocalModelGate gate(kDeviceId, kSceneHash, 1);
  LocalContactModel out;
  std::uint64_t accepted = 0;
  const long before = hapsim::test::allocation_count();
  for (std::uint64_t s = 1; s <= 1000; ++s) {  // haptic path
    const hapsim_msg_LocalModel m =
        encode_local_model(test::model_for(s), {kDeviceId, 0}, kSceneHash);
    accepted += gate.admit(m, s, out) == SampleVerdict::kAccepted ? 1 : 0;
  }
  EXPECT_EQ(hapsim::test::allocation_count() - before, 0);
  EXPECT_EQ(accepted, 1000u);
}

TEST(LocalModelGate, OrdersEachFingerOnItsOwn) {
  LocalModelGate gate(kDeviceId, kSceneHash, 2);
  LocalContactModel out;
  hapsim_msg_LocalModel finger1 = message_for(5);
  finger1.finger = 1;
  EXPECT_EQ(gate.admit(message_for(7), kNow, out), SampleVerdict::kAccepted);
  EXPECT_EQ(gate.admit(finger1, kNow, out), SampleVerdict::kAccepted);  // its own sequence
}

}  // namespace
}  // namespace hapsim::net
