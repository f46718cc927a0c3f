#include "hapsim/device/simulated_device.h"

#include "hapsim/core/error.h"

#include <cmath>

#include <gtest/gtest.h>

namespace hapsim {
namespace {

Trajectory line_trajectory() {
  std::vector<DeviceInput> s(2);
  s[0].time_s = 0.0;
  s[1].time_s = 1.0;
  s[1].p_world = Vec3(0.1, 0.0, 0.0);
  s[1].finger_rad[0] = 1.0;
  return make_trajectory(s, 1, 0, "line");
}

TEST(SimulatedDevice, PlaysTheTrajectoryByTimeAndHoldsTheEnd) {
  SimulatedDevice device(device_profile("simulated"), line_trajectory());
  EXPECT_EQ(device.profile().name, "simulated");
  DeviceInput in = device.read(0.25);
  EXPECT_NEAR(in.p_world.x(), 0.025, 1e-15);
  EXPECT_NEAR(in.finger_rad[0], 0.25, 1e-15);
  EXPECT_EQ(in.time_s, 0.25);
  EXPECT_TRUE(in.healthy);
  EXPECT_FALSE(device.finished());
  in = device.read(1.0);
  EXPECT_EQ(in.p_world.x(), 0.1);
  EXPECT_TRUE(device.finished());
  in = device.read(7.0);
  EXPECT_EQ(in.p_world.x(), 0.1);
  EXPECT_TRUE(device.finished());
  EXPECT_EQ(device.status().health, DeviceHealth::kConnected);
}

TEST(SimulatedDevice, ScriptedByAFunctionOfTime) {
  SimulatedDevice device(
      device_profile("touch"),
      [](double t) {
        DeviceInput in;
        in.p_world = Vec3(0.0, 0.0, -0.01 * t);
        in.buttons = t > 0.5 ? 1u : 0u;
        return in;
      },
      1.0);
  EXPECT_EQ(device.read(0.2).p_world.z(), -0.002);
  EXPECT_EQ(device.read(0.2).buttons, 0u);
  EXPECT_EQ(device.read(0.7).buttons, 1u);
  EXPECT_FALSE(device.finished());
  (void)device.read(1.0);
  EXPECT_TRUE(device.finished());
  EXPECT_THROW(SimulatedDevice(device_profile("touch"), SimulatedDevice::Script{}), Error);
  EXPECT_THROW(SimulatedDevice(device_profile("touch"), Trajectory{}), Error);
}

TEST(SimulatedDevice, RecordsCommandsAndPeaks) {
  SimulatedDevice device(device_profile("simulated"), line_trajectory());
  DeviceCommand cmd;
  cmd.force_world_n = Vec3(3.0, 4.0, 0.0);
  cmd.finger_count = 2;
  cmd.finger_force_n = {1.0, 2.5, 9.0, 0.0, 0.0};  // finger 2 is past finger_count: ignored
  device.write(cmd);
  cmd.force_world_n = Vec3(0.0, 1.0, 0.0);
  cmd.finger_force_n[0] = 0.5;
  device.write(cmd);
  EXPECT_EQ(device.command_count(), 2u);
  EXPECT_DOUBLE_EQ(device.peak_force_n(), 5.0);
  EXPECT_DOUBLE_EQ(device.peak_finger_force_n(), 2.5);
  EXPECT_EQ(device.last_command().force_world_n, Vec3(0.0, 1.0, 0.0));
  EXPECT_EQ(device.last_command().finger_force_n[0], 0.5);
  // A NaN must show up in the peak, not vanish.
  cmd.force_world_n.x() = std::nan("");
  device.write(cmd);
  EXPECT_TRUE(std::isinf(device.peak_force_n()));
  device.reset_command_stats();
  EXPECT_EQ(device.command_count(), 0u);
  EXPECT_EQ(device.peak_force_n(), 0.0);
}

TEST(SimulatedDevice, ReportsInjectedHealthLoss) {
  SimulatedDevice device(device_profile("simulated"), line_trajectory());
  device.set_health(DeviceHealth::kFailed, "cable unplugged");
  EXPECT_FALSE(device.read(0.1).healthy);
  EXPECT_EQ(device.status().health, DeviceHealth::kFailed);
  EXPECT_EQ(device.status().reason, "cable unplugged");
  EXPECT_EQ(to_string(device.status().health), "failed");
  device.set_health(DeviceHealth::kConnected);
  EXPECT_TRUE(device.read(0.1).healthy);
}

}  // namespace
}  // namespace hapsim
