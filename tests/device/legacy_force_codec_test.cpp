// The legacy force packet against bytes written out by hand from knee paper 001 §3.1 (four
// big-endian int32, 0..10 000 for 0..f_max): encoding, clamping, rounding, and every refusal.
#include "hapsim/device/legacy_force_codec.h"

#include <gtest/gtest.h>

#include <cmath>
#include <initializer_list>
#include <vector>

namespace hapsim {
namespace {

std::vector<std::byte> bytes(std::initializer_list<unsigned> values) {
  std::vector<std::byte> out;
  for (const unsigned v : values) {
    out.push_back(static_cast<std::byte>(v));
  }
  return out;
}

TEST(LegacyForceCodec, EncodesFractionsOfTheFingerMaximumBigEndian) {
  const LegacyEncoded e = encode_legacy_force({0.0, 1.0, 2.0, 4.0}, 4.0);
  // 0, 2500 = 0x09C4, 5000 = 0x1388, 10000 = 0x2710
  const std::vector<std::byte> expected =
      bytes({0, 0, 0, 0, 0, 0, 0x09, 0xC4, 0, 0, 0x13, 0x88, 0, 0, 0x27, 0x10});
  EXPECT_EQ(std::vector<std::byte>(e.packet.begin(), e.packet.end()), expected);
  EXPECT_EQ(e.clamped_fingers, 0);
}

TEST(LegacyForceCodec, ClampsAndCountsWhatIsOutsideTheRange) {
  const LegacyEncoded e = encode_legacy_force({-1.0, 5.0, std::nan(""), 2.0}, 4.0);
  const std::vector<std::byte> expected =
      bytes({0, 0, 0, 0, 0, 0, 0x27, 0x10, 0, 0, 0, 0, 0, 0, 0x13, 0x88});
  EXPECT_EQ(std::vector<std::byte>(e.packet.begin(), e.packet.end()), expected);
  EXPECT_EQ(e.clamped_fingers, 3);
  const LegacyEncoded no_max = encode_legacy_force({1.0, 1.0, 1.0, 1.0}, 0.0);
  EXPECT_EQ(no_max.packet, LegacyForcePacket{});
  EXPECT_EQ(no_max.clamped_fingers, 4);
}

TEST(LegacyForceCodec, RoundsToTheNearestStep) {
  // One step is f_max / 10 000 = 0.4 mN: a quarter step rounds down, three quarters up.
  LegacyFingerForces out{};
  const LegacyEncoded e = encode_legacy_force({1e-4, 3e-4, 4.0 - 1e-4, 3.99962}, 4.0);
  ASSERT_EQ(decode_legacy_force(e.packet, 4.0, out), LegacyPacketVerdict::kAccepted);
  EXPECT_EQ(out[0], 0.0);
  EXPECT_NEAR(out[1], 4e-4, 1e-15);
  EXPECT_EQ(out[2], 4.0);
  EXPECT_NEAR(out[3], 3.9996, 1e-12);
}

TEST(LegacyForceCodec, DecodesToNewtonsOfTheReceiversMaximum) {
  LegacyFingerForces out{};
  const std::vector<std::byte> packet =
      bytes({0, 0, 0, 0, 0, 0, 0x09, 0xC4, 0, 0, 0x13, 0x88, 0, 0, 0x27, 0x10});
  ASSERT_EQ(decode_legacy_force(packet, 4.0, out), LegacyPacketVerdict::kAccepted);
  EXPECT_EQ(out, (LegacyFingerForces{0.0, 1.0, 2.0, 4.0}));
  ASSERT_EQ(decode_legacy_force(packet, 8.0, out), LegacyPacketVerdict::kAccepted);
  EXPECT_EQ(out, (LegacyFingerForces{0.0, 2.0, 4.0, 8.0}));
}

TEST(LegacyForceCodec, RefusesShortLongAndOutOfRangePacketsWithoutTouchingTheOutput) {
  const LegacyFingerForces sentinel{1.5, 1.5, 1.5, 1.5};
  LegacyFingerForces out = sentinel;
  EXPECT_EQ(decode_legacy_force({}, 4.0, out), LegacyPacketVerdict::kShort);
  EXPECT_EQ(decode_legacy_force(std::vector<std::byte>(15), 4.0, out), LegacyPacketVerdict::kShort);
  EXPECT_EQ(decode_legacy_force(std::vector<std::byte>(17), 4.0, out), LegacyPacketVerdict::kLong);
  // 10 001 = 0x2711 in the last finger
  EXPECT_EQ(
      decode_legacy_force(bytes({0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0x27, 0x11}), 4.0, out),
      LegacyPacketVerdict::kOutOfRange);
  // -1 and INT32_MIN as int32
  EXPECT_EQ(decode_legacy_force(bytes({0xFF, 0xFF, 0xFF, 0xFF, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0}),
                                4.0, out),
            LegacyPacketVerdict::kOutOfRange);
  EXPECT_EQ(
      decode_legacy_force(bytes({0, 0, 0, 0, 0x80, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0}), 4.0, out),
      LegacyPacketVerdict::kOutOfRange);
  // A receiver without a usable maximum applies nothing.
  EXPECT_EQ(decode_legacy_force(std::vector<std::byte>(16), std::nan(""), out),
            LegacyPacketVerdict::kOutOfRange);
  EXPECT_EQ(out, sentinel);
  EXPECT_STREQ(legacy_verdict_name(LegacyPacketVerdict::kOutOfRange), "out of range");
}

TEST(LegacyForceCodec, RoundTripIsWithinHalfAStepAndNeverAboveTheMaximum) {
  const double max_n = 4.0;
  for (int i = 0; i <= 4000; ++i) {
    const double f = max_n * i / 4000.0;
    LegacyFingerForces out{};
    const LegacyEncoded e = encode_legacy_force({f, max_n - f, f, f}, max_n);
    ASSERT_EQ(decode_legacy_force(e.packet, max_n, out), LegacyPacketVerdict::kAccepted);
    EXPECT_LE(std::abs(out[0] - f), 0.5 * max_n / kLegacyForceFullScale + 1e-15) << f;
    EXPECT_LE(out[0], max_n);
    EXPECT_GE(out[1], 0.0);
  }
}

}  // namespace
}  // namespace hapsim
