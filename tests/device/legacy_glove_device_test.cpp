// The legacy force glove: a fixed pose, finger forces from the newest valid legacy packet while
// packets keep coming, zero and stale after 100 ms, failed after 1 s, every bad datagram counted
// and never applied. Packets are built here byte by byte (not with the encoder under test).
#include "hapsim/device/legacy_glove_device.h"

#include "hapsim/core/device_profile.h"
#include "hapsim/core/error.h"
#include "support/allocation_counter.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cstdint>
#include <deque>
#include <vector>

namespace hapsim {
namespace {

// Four values, big-endian int32.
std::vector<std::byte> packet(std::int32_t a, std::int32_t b, std::int32_t c, std::int32_t d) {
  std::vector<std::byte> out;
  for (const std::int32_t v : {a, b, c, d}) {
    const auto bits = static_cast<std::uint32_t>(v);
    for (int shift = 24; shift >= 0; shift -= 8) {
      out.push_back(static_cast<std::byte>((bits >> shift) & 0xFFU));
    }
  }
  return out;
}

class QueueSource final : public LegacyPacketSource {
 public:
  explicit QueueSource(std::deque<std::vector<std::byte>>* queue) : queue_(queue) {}
  std::optional<std::size_t> receive(std::span<std::byte> buffer) noexcept override {
    if (queue_->empty()) {
      return std::nullopt;
    }
    const std::vector<std::byte>& d = queue_->front();
    std::copy_n(d.begin(), std::min(d.size(), buffer.size()), buffer.begin());
    const std::size_t length = d.size();
    queue_->pop_front();
    return length;
  }

 private:
  std::deque<std::vector<std::byte>>* queue_;
};

struct Glove {
  std::deque<std::vector<std::byte>> queue;
  LegacyGloveDevice device{device_profile("rutgers_master"), std::make_unique<QueueSource>(&queue)};
};

TEST(LegacyGloveDevice, ReportsItsFixedPose) {
  LegacyGloveOptions options;
  options.p_world = Vec3(0.1, 0.2, 0.3);
  options.finger_rad = {0.1, 0.2, 0.3, 0.4};
  std::deque<std::vector<std::byte>> queue{packet(0, 0, 0, 0)};
  LegacyGloveDevice glove(device_profile("rutgers_master"), std::make_unique<QueueSource>(&queue),
                          options);
  const DeviceInput in = glove.read(0.5);
  EXPECT_EQ(in.time_s, 0.5);
  EXPECT_EQ(in.p_world, Vec3(0.1, 0.2, 0.3));
  EXPECT_EQ(in.finger_count, 4);
  EXPECT_EQ(in.finger_rad[3], 0.4);
  EXPECT_TRUE(in.healthy);
  EXPECT_EQ(glove.profile().name, "rutgers_master");
}

TEST(LegacyGloveDevice, RendersTheNewestValidPacketOfADrain) {
  Glove g;
  // 4 N full scale (Rutgers Master): 2500 = 1 N, 10000 = 4 N.
  g.queue = {packet(2500, 0, 0, 0), std::vector<std::byte>(7), packet(0, 5000, 0, 10000),
             packet(0, 0, 0, 10001), std::vector<std::byte>(40)};
  const DeviceInput in = g.device.read(0.0);
  EXPECT_TRUE(in.healthy);
  EXPECT_EQ(g.device.newest_finger_force_n(), (LegacyFingerForces{0.0, 2.0, 0.0, 4.0}));
  EXPECT_EQ(g.device.rendered().finger_count, 4);
  EXPECT_EQ(g.device.rendered().finger_force_n[1], 2.0);
  EXPECT_EQ(g.device.rendered().finger_force_n[3], 4.0);
  EXPECT_EQ(g.device.rendered().force_world_n, Vec3::Zero());
  EXPECT_EQ(g.device.count(LegacyPacketVerdict::kAccepted), 2U);
  EXPECT_EQ(g.device.count(LegacyPacketVerdict::kShort), 1U);
  EXPECT_EQ(g.device.count(LegacyPacketVerdict::kOutOfRange), 1U);
  EXPECT_EQ(g.device.count(LegacyPacketVerdict::kLong), 1U);
  EXPECT_TRUE(g.queue.empty());  // every pending datagram judged in one read
}

TEST(LegacyGloveDevice, BadPacketsNeverMoveTheRenderedForce) {
  Glove g;
  g.queue = {packet(2500, 2500, 2500, 2500)};
  (void)g.device.read(0.0);
  g.queue = {packet(-1, 0, 0, 0), packet(10001, 0, 0, 0), std::vector<std::byte>(16 + 1),
             std::vector<std::byte>(0), packet(INT32_MIN, 0, 0, 0)};
  (void)g.device.read(0.05);
  EXPECT_EQ(g.device.newest_finger_force_n(), (LegacyFingerForces{1.0, 1.0, 1.0, 1.0}));
  EXPECT_EQ(g.device.rendered().finger_force_n[0], 1.0);
  EXPECT_EQ(g.device.newest_received_s(), 0.0);  // the bad ones did not refresh it
}

TEST(LegacyGloveDevice, GoesStaleThenFailedWhenPacketsStopAndRecovers) {
  Glove g;
  g.queue = {packet(5000, 5000, 5000, 5000)};
  EXPECT_TRUE(g.device.read(1.0).healthy);
  EXPECT_TRUE(g.device.read(1.09).healthy);  // 90 ms: within the 100 ms
  EXPECT_EQ(g.device.rendered().finger_force_n[0], 2.0);

  EXPECT_FALSE(g.device.read(1.15).healthy);
  EXPECT_EQ(g.device.status().health, DeviceHealth::kStale);
  EXPECT_NE(g.device.status().reason.find("for more than 0.1"), std::string_view::npos)
      << g.device.status().reason;
  EXPECT_EQ(g.device.rendered().finger_force_n[0], 0.0);  // a stale force is not held
  EXPECT_EQ(g.device.newest_finger_force_n()[0], 2.0);    // but still known

  EXPECT_FALSE(g.device.read(2.01).healthy);
  EXPECT_EQ(g.device.status().health, DeviceHealth::kFailed);

  g.queue = {packet(2500, 0, 0, 0)};
  EXPECT_TRUE(g.device.read(3.0).healthy);
  EXPECT_EQ(g.device.status().health, DeviceHealth::kConnected);
  EXPECT_EQ(g.device.rendered().finger_force_n[0], 1.0);
}

TEST(LegacyGloveDevice, WaitsForTheFirstPacketThenGivesUp) {
  Glove g;
  EXPECT_FALSE(g.device.read(10.0).healthy);
  EXPECT_EQ(g.device.status().health, DeviceHealth::kStale);
  EXPECT_EQ(g.device.status().reason, "no legacy force packet yet");
  EXPECT_FALSE(g.device.read(11.5).healthy);
  EXPECT_EQ(g.device.status().health, DeviceHealth::kFailed);
  EXPECT_EQ(g.device.rendered().finger_force_n, (std::array<double, kMaxFingers>{}));
}

TEST(LegacyGloveDevice, WriteDoesNotDriveTheActuators) {
  Glove g;
  g.queue = {packet(2500, 0, 0, 0)};
  DeviceCommand c;
  c.finger_count = 4;
  c.finger_force_n = {3.0, 3.0, 3.0, 3.0};
  g.device.write(c);
  (void)g.device.read(0.0);
  EXPECT_EQ(g.device.rendered().finger_force_n[0], 1.0);
  EXPECT_EQ(g.device.rendered().finger_force_n[1], 0.0);
  EXPECT_EQ(g.device.last_command().finger_force_n[1], 3.0);
}

TEST(LegacyGloveDevice, AFloodIsDrainedAFewHundredAtATime) {
  std::deque<std::vector<std::byte>> queue(1000, packet(2500, 0, 0, 0));
  LegacyGloveOptions options;
  options.max_datagrams_per_read = 300;
  LegacyGloveDevice glove(device_profile("rutgers_master"), std::make_unique<QueueSource>(&queue),
                          options);
  (void)glove.read(0.0);
  EXPECT_EQ(queue.size(), 700U);
  EXPECT_EQ(glove.drain_capped(), 1U);
  (void)glove.read(0.001);
  (void)glove.read(0.002);
  (void)glove.read(0.003);
  EXPECT_TRUE(queue.empty());
  EXPECT_EQ(glove.count(LegacyPacketVerdict::kAccepted), 1000U);
}

TEST(LegacyGloveDevice, RefusesAProfileThePacketCannotDrive) {
  EXPECT_THROW(LegacyGloveDevice(device_profile("touch"), nullptr), Error);
  DeviceProfile no_scale = device_profile("rutgers_master");
  no_scale.max_finger_force_n = 0.0;
  EXPECT_THROW(LegacyGloveDevice(no_scale, nullptr), Error);
}

// A source replaying preallocated datagrams: the test itself allocates nothing per cycle.
class RingSource final : public LegacyPacketSource {
 public:
  explicit RingSource(std::vector<std::vector<std::byte>> datagrams)
      : datagrams_(std::move(datagrams)) {}
  std::optional<std::size_t> receive(std::span<std::byte> buffer) noexcept override {
    if (pending_ == 0) {
      return std::nullopt;
    }
    --pending_;
    const std::vector<std::byte>& d = datagrams_[next_++ % datagrams_.size()];
    std::copy_n(d.begin(), std::min(d.size(), buffer.size()), buffer.begin());
    return d.size();
  }
  void arrive(int n) { pending_ = n; }

 private:
  std::vector<std::vector<std::byte>> datagrams_;
  std::size_t next_ = 0;
  int pending_ = 0;
};

TEST(LegacyGloveDevice, ReadAllocatesNothing) {
  auto source = std::make_unique<RingSource>(std::vector<std::vector<std::byte>>{
      packet(100, 200, 300, 400), std::vector<std::byte>(3), std::vector<std::byte>(64)});
  RingSource* ring = source.get();
  LegacyGloveDevice glove(device_profile("rutgers_master"), std::move(source));
  (void)glove.read(0.0);
  const long before = test::thread_allocation_count();
  for (int i = 0; i < 2000; ++i) {
    ring->arrive(i % 4);
    (void)glove.read(1e-3 * i);
    (void)glove.status();
  }
  EXPECT_EQ(test::thread_allocation_count() - before, 0);
  EXPECT_GT(glove.count(LegacyPacketVerdict::kAccepted), 0U);
}

}  // namespace
}  // namespace hapsim
