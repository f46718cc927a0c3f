// The device another thread drives (the viewer's mouse probe): input and command hand-overs,
// the position filter against the exact first-order step response, and the link going away.
#include "hapsim/device/interactive_device.h"

#include "hapsim/core/device_profile.h"

#include <gtest/gtest.h>

#include <atomic>
#include <cmath>
#include <thread>

namespace hapsim {
namespace {

TEST(InteractiveDevice, HandsTheNewestInputAndCommandOver) {
  InteractiveDevice device(device_profile("omega3"));
  DeviceInput in;
  in.p_world = Vec3(0.1, 0.2, 0.3);
  in.buttons = 1;
  device.set_input(in);
  const DeviceInput read = device.read(0.5);
  EXPECT_EQ(read.p_world, in.p_world);
  EXPECT_EQ(read.buttons, 1U);
  EXPECT_EQ(read.time_s, 0.5);
  EXPECT_TRUE(read.healthy);
  DeviceCommand c;
  c.force_world_n = Vec3(1, 2, 3);
  device.write(c);
  EXPECT_EQ(device.last_command().force_world_n, c.force_world_n);
  device.set_connected(false);
  EXPECT_FALSE(device.read(0.6).healthy);
  EXPECT_EQ(device.status().health, DeviceHealth::kFailed);
}

TEST(InteractiveDevice, PositionFilterIsTheFirstOrderStepResponse) {
  const double tau = 0.01;
  DeviceInput start;
  start.p_world = Vec3::Zero();
  InteractiveDevice device(device_profile("omega3"), start,
                           InteractiveDeviceOptions{.position_smoothing_s = tau});
  (void)device.read(0.0);
  DeviceInput step = start;
  step.p_world = Vec3(0.010, 0.0, 0.0);  // a 10 mm jump, as one mouse frame can make
  device.set_input(step);
  double previous = 0.0;
  for (int i = 1; i <= 50; ++i) {
    const double t = 1e-3 * i;
    const double x = device.read(t).p_world.x();
    EXPECT_NEAR(x, 0.010 * (1.0 - std::exp(-t / tau)), 1e-12) << i;
    EXPECT_GT(x, previous);  // no overshoot, no jump back
    previous = x;
  }
  // Largest step of one cycle: 10 mm · (1 − e^(−0.1)) ≈ 0.95 mm instead of 10 mm.
  EXPECT_LT(0.010 * (1.0 - std::exp(-0.1)), 0.001);
}

TEST(InteractiveDevice, InputFromAnotherThreadIsNeverTorn) {
  InteractiveDevice device(device_profile("omega3"));
  std::atomic<bool> done{false};
  std::thread ui([&] {
    for (int i = 1; i <= 100'000; ++i) {
      DeviceInput in;
      in.p_world = Vec3::Constant(static_cast<double>(i));
      in.q_world = Quat::Identity();
      in.buttons = static_cast<std::uint32_t>(i);
      device.set_input(in);
    }
    done.store(true);
  });
  int torn = 0;
  while (!done.load()) {
    const DeviceInput in = device.read(0.0);
    const bool initial = in.buttons == 0;  // nothing set yet
    const bool consistent = in.p_world.x() == in.p_world.z() &&
                            (initial || in.p_world.x() == static_cast<double>(in.buttons));
    torn += consistent ? 0 : 1;
  }
  ui.join();
  EXPECT_EQ(torn, 0);
}

}  // namespace
}  // namespace hapsim
