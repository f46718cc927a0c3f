// Device driver plugins through the public C ABI: the example driver (examples/device_plugin)
// loads, its state matches the path its config describes (computed here from the config, not
// by the driver), the forces written reach it (its simulated hand yields by F / k), and every
// way a driver can be wrong is one error line or an unhealthy device that renders nothing.
#include "hapsim/device/plugin_device.h"

#include "hapsim/core/error.h"
#include "support/allocation_counter.h"

#include <gtest/gtest.h>

#include <unistd.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <numbers>
#include <string>

namespace hapsim {
namespace {

constexpr double kPi = std::numbers::pi;

// The example's path for a config, written out independently of the driver's C code.
struct ExamplePath {
  double radius_m = 0.05;
  double period_s = 2.0;
  double depth_m = 0.01;
  double press_period_s = 1.0;
  double hand_n_per_m = 500.0;
  double finger_n_per_rad = 2.0;

  [[nodiscard]] std::string config() const {
    return "radius_m=" + std::to_string(radius_m) + " period_s=" + std::to_string(period_s) +
           ",press_depth_m=" + std::to_string(depth_m) +
           " press_period_s=" + std::to_string(press_period_s) +
           " hand_stiffness_n_per_m=" + std::to_string(hand_n_per_m) + " fingers=2";
  }
  [[nodiscard]] double press(double t) const {
    return 0.5 * (1.0 - std::cos(2.0 * kPi * t / press_period_s));
  }
  [[nodiscard]] Vec3 position(double t) const {
    const double theta = 2.0 * kPi * t / period_s;
    return {radius_m * std::cos(theta), radius_m * std::sin(theta), -depth_m * press(t)};
  }
};

std::string error_of(const std::filesystem::path& path, const std::string& config = "") {
  try {
    PluginDevice device(path, config);
  } catch (const Error& e) {
    return e.what();
  }
  return "(no error)";
}

void expect_one_line_naming(const std::string& message, const std::filesystem::path& path) {
  EXPECT_EQ(message.find('\n'), std::string::npos) << message;
  EXPECT_EQ(message.rfind("plugin " + path.string() + ": ", 0), 0U) << message;
}

TEST(PluginDevice, ExampleFollowsThePathItsConfigDescribes) {
  const ExamplePath path;
  PluginDevice device(HAPSIM_EXAMPLE_DRIVER, path.config());
  for (const double t : {0.0, 0.125, 0.25, 0.5, 0.8, 1.3}) {
    const DeviceInput in = device.read(t);
    EXPECT_TRUE(in.healthy) << t;
    EXPECT_EQ(in.time_s, t);
    EXPECT_NEAR((in.p_world - path.position(t)).norm(), 0.0, 1e-12) << t;
    // The stylus is yawed along the circle's tangent: theta about z.
    const double theta = 2.0 * kPi * t / path.period_s;
    EXPECT_NEAR(in.q_world.angularDistance(Quat(Eigen::AngleAxisd(theta, Vec3::UnitZ()))), 0.0,
                1e-9)
        << t;
    const double omega = 2.0 * kPi / path.period_s;
    EXPECT_NEAR(device.velocity_world_m_per_s().x(), -path.radius_m * omega * std::sin(theta),
                1e-12);
    EXPECT_NEAR(device.velocity_world_m_per_s().y(), path.radius_m * omega * std::cos(theta),
                1e-12);
    EXPECT_EQ(in.finger_count, 2);
    EXPECT_NEAR(in.finger_rad[0], 0.6 * path.press(t), 1e-12);
    EXPECT_EQ(in.buttons, path.press(t) > 0.5 ? 1U : 0U) << t;
    EXPECT_EQ(device.status().health, DeviceHealth::kConnected);
  }
}

TEST(PluginDevice, ProfileIsTheDriversRatedLimits) {
  PluginDevice device(HAPSIM_EXAMPLE_DRIVER, "radius_m=0.05 center_z_m=0.1");
  const DeviceProfile& p = device.profile();
  EXPECT_EQ(p.name, "example-circle-press");
  EXPECT_EQ(device.driver_name(), "example-circle-press");
  EXPECT_EQ(p.display_name, "hapsim example: circle-and-press simulated stylus");
  EXPECT_EQ(p.max_force_n, 5.0);
  EXPECT_EQ(p.max_stiffness_n_per_m, 1000.0);
  EXPECT_EQ(p.max_damping_n_s_per_m, 5.0);
  EXPECT_EQ(p.finger_count, 2);
  EXPECT_EQ(p.max_finger_force_n, 2.0);
  EXPECT_FALSE(p.max_force_rate_n_per_s.has_value());
  // Workspace: the circle's reach plus 5 cm around the configured centre.
  EXPECT_NEAR((p.workspace_world.min() - Vec3(-0.1, -0.1, 0.0)).norm(), 0.0, 1e-12);
  EXPECT_NEAR((p.workspace_world.max() - Vec3(0.1, 0.1, 0.2)).norm(), 0.0, 1e-12);
  EXPECT_NE(p.source.find(HAPSIM_EXAMPLE_DRIVER), std::string::npos);
}

TEST(PluginDevice, ForcesWrittenReachTheDriver) {
  const ExamplePath path;
  PluginDevice device(HAPSIM_EXAMPLE_DRIVER, path.config());
  DeviceCommand c;
  c.force_world_n = Vec3(1.0, 0.0, -0.5);
  c.finger_count = 2;
  c.finger_force_n = {0.5, 0.0};
  device.write(c);
  const double t = 0.5;  // mid-press: the gripper is closed to 0.6 rad
  const DeviceInput in = device.read(t);
  // The simulated hand yields by F / k_hand; the finger opens by F / k_finger.
  EXPECT_NEAR((in.p_world - (path.position(t) + c.force_world_n / path.hand_n_per_m)).norm(), 0.0,
              1e-12);
  EXPECT_NEAR(in.finger_rad[0], 0.6 - 0.5 / path.finger_n_per_rad, 1e-12);
  EXPECT_NEAR(in.finger_rad[1], 0.6, 1e-12);
}

TEST(PluginDevice, ClampsCommandsToTheRatedLimitsBeforeTheDriverSeesThem) {
  const ExamplePath path;
  PluginDevice device(HAPSIM_EXAMPLE_DRIVER, path.config());
  DeviceCommand c;
  c.force_world_n = Vec3(30.0, 40.0, 0.0);  // 50 N against a 5 N rating
  c.finger_count = 5;                       // the device has 2 fingers
  c.finger_force_n = {10.0, -3.0, 7.0, 7.0, 7.0};
  device.write(c);
  EXPECT_NEAR((device.last_sent().force_world_n - Vec3(3.0, 4.0, 0.0)).norm(), 0.0, 1e-12);
  EXPECT_EQ(device.last_sent().finger_count, 2);
  EXPECT_EQ(device.last_sent().finger_force_n[0], 2.0);
  EXPECT_EQ(device.last_sent().finger_force_n[1], 0.0);
  const DeviceInput in = device.read(0.0);
  EXPECT_NEAR((in.p_world - (path.position(0.0) + Vec3(3.0, 4.0, 0.0) / path.hand_n_per_m)).norm(),
              0.0, 1e-12);
}

TEST(PluginDevice, ACommandWithANanIsSentAsZero) {
  const ExamplePath path;
  PluginDevice device(HAPSIM_EXAMPLE_DRIVER, path.config());
  DeviceCommand c;
  c.force_world_n = Vec3(1.0, 0.0, 0.0);
  c.finger_count = 1;
  c.finger_force_n[0] = std::nan("");
  device.write(c);
  EXPECT_EQ(device.last_sent().force_world_n, Vec3::Zero());
  EXPECT_EQ(device.counts().commands_zeroed, 1U);
  EXPECT_NEAR((device.read(0.2).p_world - path.position(0.2)).norm(), 0.0, 1e-12);
}

TEST(PluginDevice, ANanFromTheDriverFailsItForGood) {
  const ExamplePath path;
  PluginDevice device(HAPSIM_EXAMPLE_DRIVER, path.config() + " nan_after_s=0.1");
  const DeviceInput good = device.read(0.05);
  ASSERT_TRUE(good.healthy);
  const DeviceInput bad = device.read(0.1);
  EXPECT_FALSE(bad.healthy);
  EXPECT_EQ(bad.p_world, good.p_world);  // the last good sample, never the NaN
  EXPECT_TRUE(bad.p_world.allFinite());
  EXPECT_EQ(device.status().health, DeviceHealth::kFailed);
  EXPECT_NE(device.status().reason.find("non-finite position_m"), std::string_view::npos)
      << device.status().reason;
  // A finite command is now sent as zero: a device that lied once never pushes again.
  DeviceCommand c;
  c.force_world_n = Vec3(1.0, 0.0, 0.0);
  device.write(c);
  EXPECT_EQ(device.last_sent().force_world_n, Vec3::Zero());
  EXPECT_FALSE(device.read(0.0).healthy);  // even back before the NaN
  EXPECT_EQ(device.counts().bad_samples, 1U);
}

TEST(PluginDevice, DriverHealthIsTheDevicesStatus) {
  PluginDevice device(HAPSIM_EXAMPLE_DRIVER, "fail_after_s=0.2");
  EXPECT_EQ(device.status().health, DeviceHealth::kStale);  // opened, nothing read yet
  EXPECT_TRUE(device.read(0.1).healthy);
  EXPECT_FALSE(device.read(0.2).healthy);
  EXPECT_EQ(device.status().health, DeviceHealth::kFailed);
  EXPECT_EQ(device.status().reason, "simulated fault (fail_after_s)");
}

TEST(PluginDevice, AFrozenTimestampGoesStaleThenFailed) {
  PluginDevice device(HAPSIM_TEST_DRIVER_FROZEN, "");
  EXPECT_TRUE(device.read(0.0).healthy);
  EXPECT_TRUE(device.read(0.1).healthy);  // not more than 100 ms yet
  EXPECT_FALSE(device.read(0.15).healthy);
  EXPECT_EQ(device.status().health, DeviceHealth::kStale);
  EXPECT_NE(device.status().reason.find("no new sample"), std::string_view::npos);
  EXPECT_FALSE(device.read(1.01).healthy);
  EXPECT_EQ(device.status().health, DeviceHealth::kFailed);
}

TEST(PluginDevice, NoSampleAtAllIsNeverHealthy) {
  PluginDevice device(HAPSIM_TEST_DRIVER_NO_SAMPLE, "");
  const DeviceInput in = device.read(0.0);
  EXPECT_FALSE(in.healthy);
  EXPECT_EQ(in.p_world, Vec3::Zero());
  EXPECT_EQ(device.status().reason, "no sample from the driver yet");
  EXPECT_FALSE(device.read(2.0).healthy);
  EXPECT_EQ(device.status().health, DeviceHealth::kFailed);
  EXPECT_EQ(device.counts().no_sample, 2U);
}

TEST(PluginDevice, WrongAbiVersionIsOneLine) {
  const std::string message = error_of(HAPSIM_TEST_DRIVER_WRONG_ABI);
  expect_one_line_naming(message, HAPSIM_TEST_DRIVER_WRONG_ABI);
  EXPECT_NE(message.find("ABI version 7, expected 1"), std::string::npos) << message;
}

TEST(PluginDevice, MissingEntryPointIsOneLine) {
  const std::string message = error_of(HAPSIM_TEST_DRIVER_NO_ENTRY);
  expect_one_line_naming(message, HAPSIM_TEST_DRIVER_NO_ENTRY);
  EXPECT_NE(message.find("missing symbol hapsim_device_driver_v1"), std::string::npos) << message;
}

TEST(PluginDevice, NullFunctionIsOneLine) {
  const std::string message = error_of(HAPSIM_TEST_DRIVER_NULL_READ);
  expect_one_line_naming(message, HAPSIM_TEST_DRIVER_NULL_READ);
  EXPECT_NE(message.find("driver table has no read_state()"), std::string::npos) << message;
}

TEST(PluginDevice, BadRatedLimitsAreOneLine) {
  const std::string message = error_of(HAPSIM_TEST_DRIVER_BAD_LIMITS);
  expect_one_line_naming(message, HAPSIM_TEST_DRIVER_BAD_LIMITS);
  EXPECT_NE(message.find("rated_limits() gave max_stiffness_n_per_m = nan"), std::string::npos)
      << message;
}

TEST(PluginDevice, OpenFailureCarriesTheDriversMessageOnOneLine) {
  const std::string message = error_of(HAPSIM_TEST_DRIVER_OPEN_FAILS);
  expect_one_line_naming(message, HAPSIM_TEST_DRIVER_OPEN_FAILS);
  EXPECT_NE(message.find("open() failed: no device on /dev/fake0 plug it in"), std::string::npos)
      << message;
  const std::string config_error = error_of(HAPSIM_EXAMPLE_DRIVER, "radius_m=0.03 bogus=1");
  EXPECT_NE(config_error.find("open() failed: unknown key 'bogus'"), std::string::npos)
      << config_error;
}

TEST(PluginDevice, NotASharedObjectOrNoFileIsOneLine) {
  const std::filesystem::path text = std::filesystem::temp_directory_path() /
                                     ("hapsim_not_a_plugin_" + std::to_string(::getpid()) + ".so");
  std::ofstream(text) << "not an ELF file\n";
  const std::string message = error_of(text);
  std::filesystem::remove(text);
  expect_one_line_naming(message, text);
  EXPECT_NE(message.find("not a shared object this process can load"), std::string::npos)
      << message;
  const std::string missing = error_of("/nonexistent/driver.so");
  EXPECT_EQ(missing, "plugin /nonexistent/driver.so: no such file");
}

TEST(PluginDevice, ABareFileNameIsLoadedFromTheCurrentFolder) {
  const std::filesystem::path driver(HAPSIM_EXAMPLE_DRIVER);
  const std::filesystem::path before = std::filesystem::current_path();
  std::filesystem::current_path(driver.parent_path());
  std::string name;
  try {
    name = PluginDevice(driver.filename(), "").driver_name();
  } catch (const Error& e) {
    name = e.what();
  }
  std::filesystem::current_path(before);
  EXPECT_EQ(name, "example-circle-press");
}

TEST(PluginDevice, ReadAndWriteAllocateNothing) {
  PluginDevice device(HAPSIM_EXAMPLE_DRIVER, ExamplePath{}.config());
  DeviceCommand c;
  c.finger_count = 2;
  (void)device.read(0.0);
  device.write(c);
  const long before = test::thread_allocation_count();
  for (int i = 0; i < 2000; ++i) {
    const DeviceInput in = device.read(1e-3 * i);
    c.force_world_n = 1e-3 * in.p_world;
    device.write(c);
    (void)device.status();
  }
  EXPECT_EQ(test::thread_allocation_count() - before, 0);
}

TEST(PluginDevice, DeviceSpecNamesThePluginPath) {
  EXPECT_EQ(plugin_path_from_device_spec("plugin:/opt/drivers/libtouch.so"),
            std::filesystem::path("/opt/drivers/libtouch.so"));
  EXPECT_FALSE(plugin_path_from_device_spec("sim").has_value());
  EXPECT_FALSE(plugin_path_from_device_spec("legacy-glove").has_value());
  EXPECT_THROW((void)plugin_path_from_device_spec("plugin:"), Error);
  const std::unique_ptr<Device> device = open_plugin_device(HAPSIM_EXAMPLE_DRIVER, "");
  EXPECT_EQ(device->profile().name, "example-circle-press");
}

}  // namespace
}  // namespace hapsim
