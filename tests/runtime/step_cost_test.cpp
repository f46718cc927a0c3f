// A real-time session's "step cost" is World::step alone, as `hapsim run` reports it: a device
// whose read waits (serve's RemoteDevice waits up to --lockstep-us for the device host's state)
// makes the loop's cycle long, not the step.
#include "runtime/two_body_world.h"

#include "hapsim/core/device_profile.h"
#include "hapsim/runtime/session.h"
#include "hapsim/world/world.h"

#include <gtest/gtest.h>

#include <chrono>

namespace hapsim {
namespace {

// Holds the tool 50 mm above both bodies (no contact: a cheap step); each read spins 400 us, as
// serve's lockstep wait for a device host does.
class WaitingDevice final : public Device {
 public:
  DeviceInput read(double time_s) noexcept override {
    const auto until = std::chrono::steady_clock::now() + std::chrono::microseconds(400);
    while (std::chrono::steady_clock::now() < until) {
    }
    DeviceInput in;
    in.time_s = time_s;
    in.p_world = Vec3(0.0, 0.0, 0.05);
    return in;
  }
  void write(const DeviceCommand& /*command*/) noexcept override {}
  const DeviceProfile& profile() const noexcept override { return profile_; }
  DeviceStatus status() const noexcept override { return {}; }

 private:
  const DeviceProfile& profile_ = device_profile("omega3");
};

TEST(StepCost, ARealTimeSessionTimesTheStepNotTheDevicesWait) {
  World world(test::two_body_world());
  WaitingDevice device;
  SessionOptions options;
  options.realtime = true;
  options.duration_s = 0.3;
  const SessionSummary s = run_session(world, device, options);
  ASSERT_GT(s.steps, 100u);
  // A step out of contact on two bodies takes microseconds; the wait was 400 us every cycle.
  EXPECT_LT(s.step_us.p50, 200.0) << "the step cost holds the device's read";
  EXPECT_GT(s.step_us.p50, 0.0);
}

}  // namespace
}  // namespace hapsim
