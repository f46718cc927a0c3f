// Faults inside a running world (issue 14 item 3), asserted on what reaches the device: the device
// vanishing while the tool presses into tissue, and a NaN planted in a deformed vertex. Expected:
// no command is non-finite or above the device's rating, the force goes to exactly zero and stays
// there once the device is gone, and the world keeps stepping.
#include "runtime/two_body_world.h"

#include "hapsim/core/device_profile.h"
#include "hapsim/deform/vertex_deflection.h"
#include "hapsim/runtime/session.h"
#include "hapsim/world/world.h"

#include <gtest/gtest.h>

#include <atomic>
#include <cmath>
#include <cstdio>
#include <limits>
#include <vector>

namespace hapsim {
namespace {

using test::two_body_world;

// The tool 5 mm into the top of the soft ball (its top is at z = 0 above x = 0.2; tool radius
// 4 mm): about 1.5 N of penalty force on a deformable segment.
DeviceInput pressing_the_ball() {
  DeviceInput in;
  in.p_world = Vec3(0.2, 0.0, 0.004 - 0.005);
  return in;
}

// Presses the ball; from the first read at or after `vanish_at` that follows a write of more
// than 0.5 N (in contact), it is gone: reads are unhealthy (the last pose, as a driver that lost
// its device keeps it) and its status says so. Logs every force written (no allocation: sized).
class VanishingDevice final : public Device {
 public:
  explicit VanishingDevice(std::uint64_t vanish_at)
      : profile_(device_profile("omega3")), vanish_at_(vanish_at), forces_(20'000, -1.0) {}

  DeviceInput read(double time_s) noexcept override {
    if (!gone_.load() && reads_ >= vanish_at_ && last_force_n_ > 0.5) {
      vanished_at_write_ = writes_.load();
      gone_.store(true);
    }
    ++reads_;
    DeviceInput in = pressing_the_ball();
    in.time_s = time_s;
    in.healthy = !gone_.load();
    return in;
  }
  void write(const DeviceCommand& command) noexcept override {
    last_force_n_ = command.force_world_n.norm();
    const std::size_t i = writes_.fetch_add(1);
    if (i < forces_.size()) {
      forces_[i] =
          std::isfinite(last_force_n_) ? last_force_n_ : std::numeric_limits<double>::quiet_NaN();
    }
  }
  const DeviceProfile& profile() const noexcept override { return profile_; }
  DeviceStatus status() const noexcept override {
    DeviceStatus s;
    if (gone_.load()) {
      s.health = DeviceHealth::kFailed;
    }
    return s;
  }

  [[nodiscard]] bool gone() const { return gone_.load(); }
  [[nodiscard]] std::size_t vanished_at_write() const { return vanished_at_write_; }
  [[nodiscard]] std::vector<double> forces() const {
    return {forces_.begin(), forces_.begin() + static_cast<std::ptrdiff_t>(
                                                   std::min(writes_.load(), forces_.size()))};
  }

 private:
  DeviceProfile profile_;
  std::uint64_t vanish_at_;
  std::uint64_t reads_ = 0;
  double last_force_n_ = 0.0;
  std::atomic<bool> gone_{false};
  std::size_t vanished_at_write_ = 0;
  std::vector<double> forces_;
  std::atomic<std::size_t> writes_{0};
};

// The device vanishes mid-contact in a real-time run: from then on the force only falls, reaches
// exactly zero and stays there; the run serves to its end.
TEST(WorldFaults, DeviceVanishingMidContactRampsToZeroAndTheRunGoesOn) {
  World world(two_body_world());
  VanishingDevice device(300);
  SessionOptions options;
  options.realtime = true;
  options.duration_s = 1.0;
  options.check_pop_through = false;
  const SessionSummary s = run_session(world, device, options);
  EXPECT_EQ(s.steps, 1000u);
  ASSERT_TRUE(device.gone()) << "the tool never pressed the ball";
  const std::vector<double> f = device.forces();
  const std::size_t from = device.vanished_at_write();
  ASSERT_GT(from, 0u);
  EXPECT_GT(f[from - 1], 0.5);  // in contact when it went
  std::size_t first_zero = f.size();
  for (std::size_t i = 0; i < f.size(); ++i) {
    ASSERT_TRUE(std::isfinite(f[i])) << "write " << i;
    ASSERT_LE(f[i], device.profile().max_force_n + 1e-9) << "write " << i;
    if (i >= from) {
      EXPECT_LE(f[i], f[i - 1] + 1e-12)
          << "the force rose after the device went (write " << i << ")";
      if (f[i] == 0.0 && first_zero == f.size()) {
        first_zero = i;
      }
    }
  }
  ASSERT_LT(first_zero, f.size()) << "the force never reached zero";
  for (std::size_t i = first_zero; i < f.size(); ++i) {
    EXPECT_EQ(f[i], 0.0) << "write " << i;
  }
  EXPECT_EQ(s.max_force_limit_violations, 0u);
}

// A NaN written into the deformed vertex under the tool (a bug upstream, a bad bit), again before
// every step for 100 steps. The haptic path reads the deflection offsets (whose only input,
// contacts, VertexDeflection validates: vertex_deflection_test), never the drawn mesh, so this
// checks that the mesh stays out of it: every command finite and within the rating, every contact
// reported finite, the world stepping on, and the force on the still-pressing tool the same after.
TEST(WorldFaults, NanInADeformedVertexNeverReachesTheDevice) {
  World world(two_body_world());
  const DeviceProfile& omega = device_profile("omega3");
  const DeviceInput in = pressing_the_ball();
  const double dt_s = 0.001;
  double before_n = 0.0;
  for (int i = 0; i < 300; ++i) {
    before_n = world.step(in, dt_s).command.force_world_n.norm();
  }
  ASSERT_GT(before_n, 0.5) << "the tool does not press the ball";
  const VertexDeflection* d = world.deflection(1, 0);
  ASSERT_NE(d, nullptr);
  // The vertex nearest the contact: the ball's top, (0, 0, 0.03) in its mesh frame, deflected.
  const TriangleMesh& mesh = d->mesh();
  std::uint32_t top = 0;
  for (std::uint32_t v = 0; v < mesh.vertices.size(); ++v) {
    if ((mesh.vertices[v] - Vec3(0, 0, 0.03)).norm() <
        (mesh.vertices[top] - Vec3(0, 0, 0.03)).norm()) {
      top = v;
    }
  }
  ASSERT_GT(d->deflection_m(top), 0.0) << "the vertex under the tool is not deformed";
  const double nan = std::numeric_limits<double>::quiet_NaN();
  int nonzero_during = 0;
  for (int i = 0; i < 300; ++i) {
    if (i < 100) {
      const_cast<TriangleMesh&>(d->mesh()).vertices[top] = Vec3(nan, nan, nan);
    }
    const StepResult& r = world.step(in, dt_s);
    ASSERT_TRUE(r.command.force_world_n.allFinite()) << "step " << i;
    ASSERT_LE(r.command.force_world_n.norm(), omega.max_force_n + 1e-9) << "step " << i;
    for (const WorldContact& c : r.contacts) {
      ASSERT_TRUE(c.point_world.allFinite() && std::isfinite(c.depth_m)) << "step " << i;
    }
    nonzero_during += i < 100 && r.command.force_world_n.norm() > 0.0 ? 1 : 0;
  }
  const double after_n = world.step(in, dt_s).command.force_world_n.norm();
  EXPECT_NEAR(after_n, before_n, 0.1 * before_n) << "the force did not come back";
  std::printf("NaN vertex: %d of 100 corrupted steps still pushed (before %.3f N, after %.3f N)\n",
              nonzero_during, before_n, after_n);
}

}  // namespace
}  // namespace hapsim
