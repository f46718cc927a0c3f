#include "hapsim/script/trajectory.h"

#include "hapsim/core/error.h"
#include "support/temp_path.h"

#include <cmath>
#include <cstring>
#include <fstream>
#include <numbers>
#include <string>

#include <gtest/gtest.h>

namespace hapsim {
namespace {

bool same_bits(double a, double b) {
  return std::memcmp(&a, &b, sizeof(double)) == 0;
}

void expect_same_input(const DeviceInput& a, const DeviceInput& b) {
  EXPECT_TRUE(same_bits(a.time_s, b.time_s));
  for (int k = 0; k < 3; ++k) {
    EXPECT_TRUE(same_bits(a.p_world[k], b.p_world[k])) << "p_world[" << k << "]";
  }
  for (int k = 0; k < 4; ++k) {
    EXPECT_TRUE(same_bits(a.q_world.coeffs()[k], b.q_world.coeffs()[k])) << "q[" << k << "]";
  }
  for (std::size_t k = 0; k < a.finger_rad.size(); ++k) {
    EXPECT_TRUE(same_bits(a.finger_rad[k], b.finger_rad[k])) << "finger " << k;
  }
  for (std::size_t k = 0; k < a.joint_rad.size(); ++k) {
    EXPECT_TRUE(same_bits(a.joint_rad[k], b.joint_rad[k])) << "joint " << k;
  }
  EXPECT_EQ(a.buttons, b.buttons);
  EXPECT_EQ(a.finger_count, b.finger_count);
  EXPECT_EQ(a.joint_count, b.joint_count);
}

constexpr const char* kGood =
    "# a palpation probe\r\n"
    "# units: mm\r\n"
    "t, x, y, z, qw, qx, qy, qz, f0, f1, j0, buttons\r\n"
    "0, 10, 20, 30, 1, 0, 0, 0, 0.1, 0.2, -0.5, 0\r\n"
    "\r\n"
    "0.5, +11, 20, 30, 0.70710678, 0, 0, 0.70710678, 0.3, 0.4, 0.5, 1\r\n"
    "# a comment between rows\n"
    "1.5,12,21,29,0,0,0,1,0.5,0.6,1.5,3";

TEST(TrajectoryCsv, ParsesAGoodFile) {
  const Trajectory t = parse_trajectory_csv(kGood, "good.csv");
  ASSERT_EQ(t.size(), 3u);
  EXPECT_EQ(t.finger_count, 2);
  EXPECT_EQ(t.joint_count, 1);
  EXPECT_TRUE(t.has_buttons);
  EXPECT_DOUBLE_EQ(t.start_time_s(), 0.0);
  EXPECT_DOUBLE_EQ(t.end_time_s(), 1.5);
  // Millimetres converted to metres; angles stay radians.
  EXPECT_DOUBLE_EQ(t.samples[1].p_world.x(), 0.011);
  EXPECT_DOUBLE_EQ(t.samples[2].p_world.z(), 0.029);
  EXPECT_DOUBLE_EQ(t.samples[1].finger_rad[1], 0.4);
  EXPECT_DOUBLE_EQ(t.samples[2].joint_rad[0], 1.5);
  EXPECT_EQ(t.samples[2].buttons, 3u);
  // Hand-written 0.70710678 is normalised exactly.
  EXPECT_NEAR(t.samples[1].q_world.norm(), 1.0, 1e-15);
  EXPECT_EQ(t.samples[1].finger_count, 2);
  EXPECT_EQ(t.samples[1].finger_rad[2], 0.0);
}

struct BadCase {
  const char* name;
  std::string text;
  std::string where;  // "file:line:column"
  std::string message_part;
};

TEST(TrajectoryCsv, EveryBadFileNamesLineColumnAndExpectation) {
  const std::string h = "t,x,y,z,qw,qx,qy,qz\n";
  const std::string r0 = "0,0,0,0,1,0,0,0\n";
  const BadCase cases[] = {
      {"empty", "", "bad.csv", "no header"},
      {"only comments", "# nothing\n\n", "bad.csv", "no header"},
      {"header only", h, "bad.csv", "no data rows"},
      {"wrong first column", "time,x,y,z,qw,qx,qy,qz\n", "bad.csv:1:1", "expected 't'"},
      {"missing quaternion column", "t,x,y,z,qw,qx,qy\n0,0,0,0,1,0,0\n", "bad.csv:1:17",
       "expected 'qz'"},
      {"pose columns out of order", "t,x,y,z,qx,qw,qy,qz\n", "bad.csv:1:9", "expected 'qw'"},
      {"unknown column", "t,x,y,z,qw,qx,qy,qz,grip\n", "bad.csv:1:21", "unknown column 'grip'"},
      {"finger gap", "t,x,y,z,qw,qx,qy,qz,f1\n", "bad.csv:1:21", "expected 'f0'"},
      {"too many fingers", "t,x,y,z,qw,qx,qy,qz,f0,f1,f2,f3,f4,f5\n", "bad.csv:1:36",
       "no more finger columns"},
      {"duplicate buttons", "t,x,y,z,qw,qx,qy,qz,buttons,buttons\n", "bad.csv:1:29", "twice"},
      {"sensor gap", "t,x,y,z,qw,qx,qy,qz,s0,s2\n", "bad.csv:1:24", "expected 's1'"},
      {"joints and sensors", "t,x,y,z,qw,qx,qy,qz,j0,s0\n", "bad.csv:1:1", "not both"},
      {"NaN count", "t,x,y,z,qw,qx,qy,qz,s0\n0,0,0,0,1,0,0,0,nan\n", "bad.csv:2:17",
       "column 's0': expected a finite"},
      {"NaN", h + r0 + "1,0,nan,0,1,0,0,0\n", "bad.csv:3:5", "column 'y': expected a finite"},
      {"inf", h + r0 + "1,0,0,-inf,1,0,0,0\n", "bad.csv:3:7", "column 'z': expected a finite"},
      {"not a number", h + r0 + "1,0,0,0,1,0,abc,0\n", "bad.csv:3:13",
       "column 'qy': expected a number, got 'abc'"},
      {"empty field", h + "0,,0,0,1,0,0,0\n", "bad.csv:2:3", "column 'x': expected a number"},
      {"trailing junk", h + "0,0,0,0,1x,0,0,0\n", "bad.csv:2:9", "got '1x'"},
      {"missing field", h + r0 + "1,0,0,0,1,0,0\n", "bad.csv:3:14", "7 fields, expected 8"},
      {"extra field", h + r0 + "1,0,0,0,1,0,0,0,9\n", "bad.csv:3:17", "9 fields, expected 8"},
      {"time equal", h + r0 + "0,0,0,0,1,0,0,0\n", "bad.csv:3:1", "must strictly increase"},
      {"time decreasing", h + "1,0,0,0,1,0,0,0\n0.5,0,0,0,1,0,0,0\n", "bad.csv:3:1",
       "not greater than the previous"},
      {"zero quaternion", h + "0,0,0,0,0,0,0,0\n", "bad.csv:2:9", "unit quaternion"},
      {"non-unit quaternion", h + "0,0,0,0,1,1,0,0\n", "bad.csv:2:9", "norm 1.414"},
      {"bad buttons", "t,x,y,z,qw,qx,qy,qz,buttons\n0,0,0,0,1,0,0,0,-1\n", "bad.csv:2:17",
       "column 'buttons': expected an unsigned integer"},
      {"units after header", h + "# units: mm\n" + r0, "bad.csv:2:1", "before the header"},
      {"unknown unit", "# units: inch\n" + h + r0, "bad.csv:1:1", "unknown unit 'inch'"},
  };
  for (const BadCase& c : cases) {
    SCOPED_TRACE(c.name);
    try {
      (void)parse_trajectory_csv(c.text, "bad.csv");
      ADD_FAILURE() << "accepted a bad file: " << c.name;
    } catch (const Error& e) {
      EXPECT_EQ(e.where(), c.where) << e.what();
      EXPECT_NE(std::string(e.what()).find(c.message_part), std::string::npos) << e.what();
    }
  }
}

// A glove's raw sensor counts (docs/glove-calibration.md) are kept per row, in column order, and
// written back as they were read.
TEST(TrajectoryCsv, RawSensorColumnsAreKeptPerRowAndSavedBack) {
  const Trajectory t = parse_trajectory_csv(
      "t,x,y,z,qw,qx,qy,qz,s0,s1,s2,buttons\n0,0,0,0,1,0,0,0,10,20,30,1\n"
      "0.5,0,0,0,1,0,0,0,11,-21,31.5,0\n",
      "raw.csv");
  ASSERT_EQ(t.sensor_count, 3);
  ASSERT_EQ(t.size(), 2u);
  EXPECT_EQ(t.joint_count, 0);
  EXPECT_EQ(std::vector<double>(t.sensors(1).begin(), t.sensors(1).end()),
            (std::vector<double>{11.0, -21.0, 31.5}));
  EXPECT_EQ(t.samples[0].buttons, 1u);
  const Trajectory again = parse_trajectory_csv(format_trajectory_csv(t), "again.csv");
  EXPECT_EQ(again.sensor_counts, t.sensor_counts);
  EXPECT_EQ(again.sensor_count, 3);
}

TEST(TrajectoryCsv, MissingFileIsNamed) {
  const auto path = test::temp_path("_missing.csv");
  try {
    (void)load_trajectory_csv(path);
    FAIL() << "expected hapsim::Error";
  } catch (const Error& e) {
    EXPECT_EQ(e.where(), path.string());
  }
}

TEST(TrajectoryCsv, SaveAndLoadIsBitExact) {
  std::vector<DeviceInput> samples(4);
  for (int i = 0; i < 4; ++i) {
    DeviceInput& s = samples[static_cast<std::size_t>(i)];
    s.time_s = 0.1 * i + 1.0 / 3.0;
    s.p_world = Vec3(std::sqrt(2.0) * i, -0.0, 1e-300 * i);
    s.q_world = Quat(Eigen::AngleAxisd(0.3 * i + 0.1, Vec3(1, 2, 3).normalized()));
    s.finger_rad[0] = std::numbers::pi / (i + 1);
    s.joint_rad[2] = -1.0 / 7.0 * i;
    s.buttons = static_cast<std::uint32_t>(i);
  }
  const Trajectory original = make_trajectory(samples, 1, 3, "code");
  const auto path = test::temp_path(".csv");
  save_trajectory_csv(original, path);
  const Trajectory loaded = load_trajectory_csv(path);
  std::filesystem::remove(path);
  ASSERT_EQ(loaded.size(), original.size());
  EXPECT_EQ(loaded.finger_count, 1);
  EXPECT_EQ(loaded.joint_count, 3);
  for (std::size_t i = 0; i < loaded.size(); ++i) {
    SCOPED_TRACE(i);
    expect_same_input(loaded.samples[i], original.samples[i]);
  }
}

Trajectory two_sample_trajectory() {
  std::vector<DeviceInput> s(3);
  s[0].time_s = 1.0;
  s[0].p_world = Vec3(0.0, -0.0, 1.0);
  s[0].finger_rad[0] = 0.2;
  s[0].joint_rad[0] = 1.0;
  s[0].buttons = 1;
  s[1].time_s = 2.0;
  s[1].p_world = Vec3(1.0, 2.0, -3.0);
  s[1].q_world = Quat(Eigen::AngleAxisd(std::numbers::pi / 2, Vec3::UnitZ()));
  s[1].finger_rad[0] = 0.6;
  s[1].joint_rad[0] = -1.0;
  s[1].buttons = 2;
  s[2].time_s = 4.0;
  s[2].p_world = Vec3(3.0, 2.0, -3.0);
  s[2].q_world = Quat(Eigen::AngleAxisd(std::numbers::pi, Vec3::UnitZ()));
  return make_trajectory(s, 1, 1, "code");
}

TEST(TrajectoryInterpolation, ExactAtSamples) {
  const Trajectory t = two_sample_trajectory();
  for (const DeviceInput& s : t.samples) {
    SCOPED_TRACE(s.time_s);
    expect_same_input(t.sample_at(s.time_s), s);
  }
}

TEST(TrajectoryInterpolation, LinearBetweenSamplesAndHeldOutside) {
  const Trajectory t = two_sample_trajectory();
  for (const double u : {0.1, 0.25, 0.5, 0.9}) {
    SCOPED_TRACE(u);
    const DeviceInput in = t.sample_at(1.0 + u);
    EXPECT_NEAR(in.p_world.x(), u * 1.0, 1e-15);
    EXPECT_NEAR(in.p_world.y(), u * 2.0, 1e-15);
    EXPECT_NEAR(in.p_world.z(), 1.0 - 4.0 * u, 1e-15);
    EXPECT_NEAR(in.finger_rad[0], 0.2 + 0.4 * u, 1e-15);
    EXPECT_NEAR(in.joint_rad[0], 1.0 - 2.0 * u, 1e-15);
    EXPECT_EQ(in.buttons, 1u);  // held from the earlier sample
    EXPECT_EQ(in.time_s, 1.0 + u);
  }
  // Second segment is twice as long: the weight follows time, not the sample index.
  EXPECT_NEAR(t.sample_at(3.0).p_world.x(), 2.0, 1e-15);
  // Held before the start and after the end.
  EXPECT_EQ(t.sample_at(-5.0).p_world, t.samples.front().p_world);
  EXPECT_EQ(t.sample_at(-5.0).time_s, -5.0);
  EXPECT_EQ(t.sample_at(99.0).p_world, t.samples.back().p_world);
  EXPECT_EQ(t.sample_at(99.0).buttons, 0u);
}

TEST(TrajectoryInterpolation, SlerpIsUnitAndFollowsTheShorterArc) {
  const Trajectory t = two_sample_trajectory();
  for (double time = 0.5; time <= 4.5; time += 0.01) {
    EXPECT_NEAR(t.sample_at(time).q_world.norm(), 1.0, 1e-14) << time;
  }
  // Halfway between 0 and 90 degrees about z: 45 degrees about z.
  const Quat mid = t.sample_at(1.5).q_world;
  const Quat expected(Eigen::AngleAxisd(std::numbers::pi / 4, Vec3::UnitZ()));
  EXPECT_NEAR(mid.angularDistance(expected), 0.0, 1e-12);
  // Constant angular velocity: a quarter of the way is a quarter of the angle.
  EXPECT_NEAR(t.sample_at(1.25).q_world.angularDistance(t.samples[0].q_world), std::numbers::pi / 8,
              1e-12);

  // q and -q are the same rotation: the interpolation must not swing through 360 degrees.
  std::vector<DeviceInput> s(2);
  s[0].q_world = Quat(Eigen::AngleAxisd(0.2, Vec3::UnitX()));
  s[1].time_s = 1.0;
  s[1].q_world = Quat(-s[0].q_world.coeffs());
  const Trajectory flip = make_trajectory(s, 0, 0, "code");
  EXPECT_NEAR(flip.sample_at(0.5).q_world.angularDistance(s[0].q_world), 0.0, 1e-12);
}

TEST(Trajectory, MakeTrajectoryRejectsBadWaypoints) {
  std::vector<DeviceInput> s(2);
  s[1].time_s = 0.0;  // not after the first
  EXPECT_THROW((void)make_trajectory(s, 0, 0, "waypoints"), Error);
  s[1].time_s = 1.0;
  s[1].p_world.x() = std::nan("");
  EXPECT_THROW((void)make_trajectory(s, 0, 0, "waypoints"), Error);
  s[1].p_world.x() = 0.0;
  s[1].q_world.coeffs() << 0, 0, 0, 2;
  EXPECT_THROW((void)make_trajectory(s, 0, 0, "waypoints"), Error);
  EXPECT_THROW((void)make_trajectory({}, 0, 0, "waypoints"), Error);
  s[1].q_world = Quat::Identity();
  EXPECT_THROW((void)make_trajectory(s, kMaxFingers + 1, 0, "waypoints"), Error);
  EXPECT_NO_THROW((void)make_trajectory(s, kMaxFingers, kMaxDeviceJoints, "waypoints"));
}

}  // namespace
}  // namespace hapsim
