// run_session: the runner around World::step. Checked against what the scripted device did (steps,
// contact counts against the trajectory's geometry), the device's rated limits, an exact replay of
// the session's own recording, and nearest-rank percentiles on known samples.
#include "hapsim/runtime/session.h"

#include "runtime/two_body_world.h"

#include "hapsim/core/device_profile.h"
#include "hapsim/core/error.h"
#include "hapsim/device/recording.h"
#include "hapsim/device/simulated_device.h"
#include "hapsim/geometry/procedural.h"

#include <gtest/gtest.h>

#include <unistd.h>
#include <algorithm>
#include <cmath>
#include <filesystem>
#include <numeric>
#include <string>

namespace hapsim {
namespace {

using test::two_body_world;

// 0-1 s: press the bone 10 mm deep at 1 m/s-ish speeds (fast enough to tunnel without a proxy);
// 1-2 s: press the soft ball 5 mm; then hover.
DeviceInput script(double t) {
  DeviceInput in;
  in.time_s = t;
  const double r = 0.004;
  if (t < 1.0) {
    // Triangle wave between 20 mm above and 10 mm into the bone, 4 round trips: 0.24 m/s.
    const double phase = std::fmod(t * 4.0, 1.0);
    const double z = phase < 0.5 ? 0.02 - 0.06 * phase : -0.01 + 0.06 * (phase - 0.5);
    in.p_world = Vec3(0.0, 0.0, z + r);
  } else if (t < 2.0) {
    const double depth = 0.005 * std::sin(3.141592653589793 * (t - 1.0));
    in.p_world = Vec3(0.2, 0.0, r - depth);
  } else {
    in.p_world = Vec3(0.1, 0.0, 0.05);
  }
  return in;
}

std::filesystem::path temp_path(const std::string& name) {
  return std::filesystem::temp_directory_path() /
         ("hapsim_session_" + std::to_string(::getpid()) + "_" + name);
}

TEST(Session, CountsContactsWithinLimitsWithoutPopThrough) {
  const DeviceProfile& omega = device_profile("omega3");
  WorldOptions wo;
  wo.max_stiffness_n_per_m = omega.max_stiffness_n_per_m;
  World world(two_body_world(), wo);
  SimulatedDevice device(omega, script, 3.0);
  SessionOptions options;
  options.duration_s = 3.0;
  int progress_calls = 0;
  double last_fraction = 0.0;
  options.progress = [&](std::string_view, double f) {
    ++progress_calls;
    EXPECT_GE(f, last_fraction);
    last_fraction = f;
  };
  const SessionSummary s = run_session(world, device, options);
  EXPECT_EQ(s.steps, 3000u);
  EXPECT_DOUBLE_EQ(s.simulated_s, 3.0);
  EXPECT_EQ(last_fraction, 1.0);
  EXPECT_GT(progress_calls, 10);
  EXPECT_EQ(s.pop_throughs, 0u);
  // The proxy sphere may rest within the god-object's contact tolerance, not deeper.
  EXPECT_LT(s.max_proxy_penetration_m, 1e-4);
  EXPECT_EQ(s.max_force_limit_violations, 0u);
  EXPECT_EQ(s.nonfinite_commands, 0u);
  ASSERT_EQ(s.segments.size(), 2u);
  ASSERT_EQ(s.tools.size(), 1u);
  // The script is below the bone's top face (tool sphere touching: z < r) for 1/3 of each
  // 250 ms period of the first second: 250 ms of contact in all, to within a step per crossing.
  EXPECT_NEAR(static_cast<double>(s.segments[0].contacts), 333.0, 12.0);
  // The soft ball is pressed for the whole second (depth > 0 strictly inside (1, 2) s).
  EXPECT_NEAR(static_cast<double>(s.segments[1].contacts), 999.0, 3.0);
  // Deflection of the penalty ball: its surface follows the tool, at most the 5 mm pressed.
  EXPECT_GT(s.segments[1].max_deflection_m, 0.003);
  EXPECT_LE(s.segments[1].max_deflection_m, 0.005 + 1e-9);
  EXPECT_EQ(s.segments[0].max_deflection_m, 0.0);  // static body
  // The bone is pressed 10 mm with k clamped to the omega.3's 5000 N/m... by the material's
  // 3000 N/m: 30 N, above the device's 12 N: the device gets its rated maximum.
  EXPECT_GT(s.segments[0].peak_force_n, 12.0);
  EXPECT_LE(s.tools[0].peak_force_n, omega.max_force_n);
  EXPECT_NEAR(s.tools[0].peak_force_n, omega.max_force_n, 1e-6);
  EXPECT_GT(s.clamped_cycles, 0u);
  // The soft ball peaks at k·5 mm = 1.5 N (below its 2 N cap).
  EXPECT_NEAR(s.segments[1].peak_force_n, 1.5, 0.1);
  EXPECT_GT(s.tools[0].mean_force_n, 0.0);
  EXPECT_LT(s.tools[0].mean_force_n, s.tools[0].peak_force_n);
  EXPECT_GT(s.step_us.p50, 0.0);
  EXPECT_LE(s.step_us.p50, s.step_us.p99);
  EXPECT_LE(s.step_us.p99, s.step_us.max);
  const std::string text = format_session_summary(s);
  EXPECT_NE(text.find("pop-throughs: 0"), std::string::npos) << text;
  EXPECT_NE(text.find("soft/ball"), std::string::npos) << text;
}

TEST(Session, RecordingReplaysBitForBit) {
  const DeviceProfile& omega = device_profile("omega3");
  const auto path = temp_path("a.rec");
  {
    World world(two_body_world());
    SimulatedDevice device(omega, script, 2.5);
    SessionRecorder recorder(path, world.content_hash(), 512);
    SessionOptions options;
    options.duration_s = 2.5;
    options.recorder = &recorder;
    const SessionSummary s = run_session(world, device, options);
    recorder.close();
    EXPECT_EQ(s.recorded_frames, 2500u);
    EXPECT_EQ(s.recording_dropped_frames, 0u);
  }
  const Recording original = read_recording(path);
  ASSERT_EQ(original.frames.size(), 2500u);
  World world(two_body_world());
  ReplayDevice replay(omega, original.frames);
  const auto again_path = temp_path("b.rec");
  SessionRecorder recorder(again_path, world.content_hash(), 512);
  SessionOptions options;
  options.duration_s = 2.5;
  options.recorder = &recorder;
  (void)run_session(world, replay, options);
  recorder.close();
  const RecordingDifference d = compare_recordings(original, read_recording(again_path));
  EXPECT_TRUE(d.identical) << d.message;
  // And a changed world is noticed: a softer bone changes the forces.
  WorldDescription softer = two_body_world();
  softer.materials[0].contact.stiffness_n_per_m = 2000.0;
  World other(softer);
  ReplayDevice replay2(omega, original.frames);
  const auto other_path = temp_path("c.rec");
  SessionRecorder recorder2(other_path, world.content_hash(), 512);
  options.recorder = &recorder2;
  (void)run_session(other, replay2, options);
  recorder2.close();
  const RecordingDifference d2 = compare_recordings(original, read_recording(other_path));
  EXPECT_FALSE(d2.identical);
  EXPECT_NE(d2.field.find("command"), std::string::npos) << d2.message;
  std::filesystem::remove(path);
  std::filesystem::remove(again_path);
  std::filesystem::remove(other_path);
}

TEST(Session, UnhealthyDeviceGetsNoForce) {
  const DeviceProfile& omega = device_profile("omega3");
  World world(two_body_world());
  SimulatedDevice device(omega, script, 1.0);
  device.set_health(DeviceHealth::kFailed, "cable pulled");
  SessionOptions options;
  options.duration_s = 1.0;
  const SessionSummary s = run_session(world, device, options);
  EXPECT_EQ(s.peak_command_force_n, 0.0);
  EXPECT_EQ(device.peak_force_n(), 0.0);
  EXPECT_EQ(s.max_force_limit_violations, 0u);
}

TEST(Session, BadOptionsAreErrors) {
  World world(two_body_world());
  SimulatedDevice device(device_profile("touch"), script, 1.0);
  SessionOptions options;
  options.duration_s = 0.0;
  EXPECT_THROW((void)run_session(world, device, options), Error);
  options.duration_s = std::nan("");
  EXPECT_THROW((void)run_session(world, device, options), Error);
  options.duration_s = 1.0;
  options.dt_s = -0.001;
  EXPECT_THROW((void)run_session(world, device, options), Error);
}

// A tool pushed through a thin penalty plate is a pop-through in the run's summary, even though
// no proxy segment is involved (the world reports it when the tool leaves through the far side).
TEST(Session, ToolPushedThroughAPenaltyPlateIsAPopThrough) {
  WorldDescription w;
  w.name = "plate";
  MaterialDescription m;
  m.name = "membrane";
  m.response = ContactResponse::kPenalty;
  m.contact.stiffness_n_per_m = 300.0;
  m.contact.max_penetration_m = 0.05;
  m.contact.max_force_n = 5.0;
  w.materials.push_back(m);
  BodyDescription body;
  body.name = "plate";
  SegmentDescription seg;
  seg.name = "plate";
  seg.mesh = make_box(Vec3(0.05, 0.05, 0.001));  // 2 mm thick, centred on z = 0
  body.segments.push_back(std::move(seg));
  w.bodies.push_back(std::move(body));
  w.tools.push_back(ToolDescription{"tip", 0.0, Vec3::Zero(), -1});
  World world(std::move(w));
  SimulatedDevice device(
      device_profile("omega3"),
      [](double t) {
        DeviceInput in;
        in.time_s = t;
        in.p_world = Vec3(0.0, 0.0, 0.01 - 0.02 * t);  // 10 mm above to 10 mm below in 1 s
        return in;
      },
      1.0);
  SessionOptions options;
  options.duration_s = 1.0;
  const SessionSummary s = run_session(world, device, options);
  EXPECT_EQ(s.pop_throughs, 1u);
  EXPECT_GT(s.segments[0].contacts, 0u);
}

// A material stiffer than the device's rating is rendered at the rating: the summary says so
// once, naming it, its own stiffness and the clamp. The bone (3000 N/m, two_body_world.h) on a
// Touch (rated 400 N/m, device_profile_test) is; the 300 N/m muscle is not; nor is a stiffer
// material no segment uses.
TEST(Session, NamesTheMaterialsClampedToTheDevicesStiffness) {
  const DeviceProfile& touch = device_profile("touch");
  WorldDescription w = two_body_world();
  w.materials.push_back(test::material("unused", ContactResponse::kProxy, 9000.0, 10.0));
  WorldOptions wo;
  wo.max_stiffness_n_per_m = touch.max_stiffness_n_per_m;
  World world(std::move(w), wo);
  SimulatedDevice device(touch, script, 0.01);
  SessionOptions options;
  options.duration_s = 0.01;
  const SessionSummary s = run_session(world, device, options);
  ASSERT_EQ(s.stiffness_clamps.size(), 1u);
  EXPECT_EQ(s.stiffness_clamps[0].material, "bone");
  EXPECT_EQ(s.stiffness_clamps[0].stiffness_n_per_m, 3000.0);
  EXPECT_EQ(s.stiffness_clamps[0].clamped_n_per_m, 400.0);
  const std::string text = format_session_summary(s);
  const std::string line =
      "stiffness clamped to the device's rated 400 N/m: material 'bone' "
      "3000 N/m\n";
  ASSERT_NE(text.find(line), std::string::npos) << text;
  EXPECT_EQ(text.find("stiffness clamped", text.find(line) + 1), std::string::npos) << text;

  // On an omega.3 (5000 N/m) nothing is clamped and nothing is said.
  WorldOptions omega;
  omega.max_stiffness_n_per_m = device_profile("omega3").max_stiffness_n_per_m;
  World unclamped(two_body_world(), omega);
  SimulatedDevice device2(touch, script, 0.01);
  const SessionSummary u = run_session(unclamped, device2, options);
  EXPECT_TRUE(u.stiffness_clamps.empty());
  EXPECT_EQ(format_session_summary(u).find("stiffness"), std::string::npos);
}

}  // namespace
}  // namespace hapsim
