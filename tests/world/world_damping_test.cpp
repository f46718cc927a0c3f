// World::step's damping against the analytic answer: a point tool entering the flat top face of a
// block at a known constant speed v feels (k·x + c·v)·n at each step (x its depth below the face,
// n the face's normal), until the material's caps (maximum penetration, maximum force) — for the
// penalty response and for the proxy (god-object) response, whose spring to the proxy carries the
// same normal damping. The expected force is computed here from the description's k, c and the
// tool's path, not from the world's reported depth.
#include "hapsim/geometry/procedural.h"
#include "hapsim/world/world.h"
#include "hapsim/world/world_stages.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

namespace hapsim {
namespace {

constexpr double kStiffness = 500.0;  // N/m
constexpr double kDamping = 4.0;      // N·s/m: c·v = 0.2 N at 50 mm/s, well above rounding
constexpr double kMaxPenetration = 0.008;
constexpr double kSpeed = 0.05;  // m/s into the block
constexpr double kDt = 1e-3;

// A block whose top face is the plane z = 0; one material, no passivity floor (it would raise c).
WorldDescription block_world(ContactResponse response, double max_force_n) {
  WorldDescription w;
  w.name = "damped block";
  MaterialDescription m;
  m.name = "damped";
  m.response = response;
  m.contact.stiffness_n_per_m = kStiffness;
  m.contact.damping_n_s_per_m = kDamping;
  m.contact.max_penetration_m = kMaxPenetration;
  m.contact.max_force_n = max_force_n;
  w.materials.push_back(m);
  w.passivity_damping_factor = 0.0;
  BodyDescription body;
  body.name = "block";
  body.kind = BodyKind::kStatic;
  body.X_world_body = Iso3(Eigen::Translation3d(0, 0, -0.02));
  SegmentDescription seg;
  seg.name = "block";
  seg.mesh = make_box(Vec3(0.05, 0.05, 0.02));
  body.segments.push_back(std::move(seg));
  w.bodies.push_back(std::move(body));
  ToolDescription tool;
  tool.name = "tip";
  tool.radius_m = 0.0;
  w.tools.push_back(tool);
  return w;
}

// (k·x + c·v) with the spring stopped at the maximum penetration, capped at the maximum force.
double expected_force_n(double depth_m, double max_force_n) {
  return std::min(kStiffness * std::min(depth_m, kMaxPenetration) + kDamping * kSpeed, max_force_n);
}

// Moves the tool down from 1 mm above the face at kSpeed to 12 mm deep and checks every step.
// Returns how many steps were in each regime, so the caller can see all three were crossed.
struct Regimes {
  int linear = 0;
  int penetration_capped = 0;
  int force_capped = 0;
};

Regimes expect_damped_entry(ContactResponse response, double max_force_n, double tolerance_n) {
  World world(block_world(response, max_force_n));
  // The world's own material is the description's (no device clamp, no passivity floor): the
  // expected values below use the description's k and c.
  const ContactMaterial effective = world.effective_material(0, kDt);
  EXPECT_EQ(effective.stiffness_n_per_m, kStiffness);
  EXPECT_EQ(effective.damping_n_s_per_m, kDamping);
  Regimes seen;
  const double z0 = 0.001;
  for (int i = 0;; ++i) {
    const double z = z0 - kSpeed * kDt * i;
    if (z < -0.012) {
      break;
    }
    DeviceInput in;
    in.time_s = kDt * i;
    in.p_world = Vec3(0.001, 0.002, z);
    const StepResult& r = world.step(in, kDt);
    const Vec3 f = r.tools[0].force_world_n;
    const double depth = -z;
    if (depth <= 0.0) {
      EXPECT_EQ(f, Vec3::Zero()) << "above the face at step " << i;
      continue;
    }
    if (i == 0) {
      continue;  // no previous position: no speed yet
    }
    const double expected = expected_force_n(depth, max_force_n);
    EXPECT_NEAR(f.z(), expected, tolerance_n) << "step " << i << ", depth " << depth;
    EXPECT_NEAR(f.head<2>().norm(), 0.0, 1e-9) << "step " << i;
    if (expected >= max_force_n) {
      ++seen.force_capped;
    } else if (depth > kMaxPenetration) {
      ++seen.penetration_capped;
    } else {
      ++seen.linear;
    }
  }
  return seen;
}

// Two blocks each: one whose force cap (4.1 N) comes first, at k·x + c·v = 4.1 N (x = 7.8 mm),
// and one whose penetration cap (8 mm) comes first, after which the force stays k·8 mm + c·v.
constexpr double kForceCapFirst = 4.1;
constexpr double kPenetrationCapFirst = 100.0;

TEST(WorldDamping, PenaltyEntryAtConstantSpeedFeelsKxPlusCv) {
  // The penalty response reads the depth from the face exactly: rounding only.
  const Regimes force_cap = expect_damped_entry(ContactResponse::kPenalty, kForceCapFirst, 1e-9);
  EXPECT_GT(force_cap.linear, 100);
  EXPECT_GT(force_cap.force_capped, 50);
  const Regimes depth_cap =
      expect_damped_entry(ContactResponse::kPenalty, kPenetrationCapFirst, 1e-9);
  EXPECT_GT(depth_cap.linear, 100);
  EXPECT_GT(depth_cap.penetration_capped, 50);
}

TEST(WorldDamping, ProxyEntryAtConstantSpeedFeelsKxPlusCv) {
  // The proxy rests on the face within its solver's tolerance (as in world_test's proxy checks):
  // k·20 µm = 0.01 N, twenty times below the damping term c·v = 0.2 N being checked.
  const double tolerance_n = kStiffness * 2e-5;
  const Regimes force_cap =
      expect_damped_entry(ContactResponse::kProxy, kForceCapFirst, tolerance_n);
  EXPECT_GT(force_cap.linear, 100);
  EXPECT_GT(force_cap.force_capped, 50);
  const Regimes depth_cap =
      expect_damped_entry(ContactResponse::kProxy, kPenetrationCapFirst, tolerance_n);
  EXPECT_GT(depth_cap.linear, 100);
  EXPECT_GT(depth_cap.penetration_capped, 50);
}

// A served world steps on a remote device's states, which after a stall arrive in bursts: here
// the device's input holds for nine steps, then moves ten periods' motion at once, its own time
// stamps saying so. The damping feels the device's speed (c·v on the step that moves, nothing
// while it holds), not ten times it from differencing over one step.
TEST(WorldDamping, InputsInBurstsFeelTheDevicesSpeedByTheirOwnTimeStamps) {
  World world(block_world(ContactResponse::kPenalty, kPenetrationCapFirst));
  constexpr int kBurst = 10;
  int moving_steps_checked = 0;
  for (int i = 0; i < 2000; ++i) {
    const int device_period = (i / kBurst) * kBurst;  // the newest state the device got through
    const double z = 0.001 - kSpeed * kDt * device_period;
    if (z < -kMaxPenetration) {
      break;
    }
    DeviceInput in;
    in.time_s = kDt * device_period;
    in.p_world = Vec3(0.001, 0.002, z);
    const Vec3 f = world.step(in, kDt).tools[0].force_world_n;
    const double depth = -z;
    if (depth <= 0.0 || i < kBurst) {
      continue;
    }
    const bool moved = i % kBurst == 0;
    const double expected = kStiffness * depth + (moved ? kDamping * kSpeed : 0.0);
    EXPECT_NEAR(f.z(), expected, 1e-9) << "step " << i << (moved ? " (moved)" : " (held)");
    moving_steps_checked += moved ? 1 : 0;
  }
  EXPECT_GT(moving_steps_checked, 10);
}

TEST(WorldDamping, InputMotionTimeIsTheStampsDifferenceOnlyWhenItSaysMore) {
  EXPECT_EQ(stage::input_motion_time_s(0.010, 0.000, kDt), 0.010);  // ten periods in one step
  EXPECT_DOUBLE_EQ(stage::input_motion_time_s(0.0105, 0.010, kDt), 0.0005);  // a fast device
  EXPECT_EQ(stage::input_motion_time_s(0.3 + kDt, 0.3, kDt), kDt);  // the step's clock: its dt
  EXPECT_EQ(stage::input_motion_time_s(0.0, 0.0, kDt), kDt);        // no stamps (Python)
  EXPECT_EQ(stage::input_motion_time_s(1.0, 2.0, kDt), kDt);        // a clock gone back
  EXPECT_EQ(stage::input_motion_time_s(1.0, 0.5, kDt), kDt);        // a gap: a jump
  EXPECT_EQ(stage::input_motion_time_s(std::nan(""), 0.5, kDt), kDt);
}

}  // namespace
}  // namespace hapsim
