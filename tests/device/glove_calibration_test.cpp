// Glove calibration (issue 16 item 1): the fit recovers a synthetic glove's known offsets, gains
// and couplings from noisy, integer counts to within five of their standard errors — computed
// here independently from the noise level and the procedure's design, σ²(XᵀX)⁻¹ — its residuals
// are the noise seen through the inverse, and it refuses a dead sensor, a bad fit, a missing
// pose and poses that cannot tell a sensor's two joints apart, each naming the sensor or joint.
#include "hapsim/device/glove_calibration.h"
#include "hapsim/core/error.h"

#include <gtest/gtest.h>

#include <Eigen/Dense>

#include <cmath>
#include <numbers>
#include <random>
#include <string>
#include <vector>

namespace hapsim {
namespace {

constexpr double kRad = std::numbers::pi / 180.0;

// The synthetic glove: counts_s = o_s + a_s·θ_joint + b_s·θ_coupled (counts per radian).
struct TrueSensor {
  double offset = 0.0;
  double a = 0.0;
  double b = 0.0;
};

std::array<TrueSensor, kGloveSensors> true_glove() {
  std::array<TrueSensor, kGloveSensors> t{};
  for (int s = 0; s < kGloveSensors; ++s) {
    TrueSensor& x = t[static_cast<std::size_t>(s)];
    x.offset = 40.0 + 7.0 * s;
    // About 60-110 counts per radian (an 8-bit DataGlove spans ~150 counts over a fist); the
    // spread sensors on the little-finger side read the other way.
    x.a = (60.0 + 3.5 * s) * (s == 12 || s == 13 ? -1.0 : 1.0);
    x.b = glove_sensor_layout()[static_cast<std::size_t>(s)].coupled_joint >= 0 ? 0.2 * x.a : 0.0;
  }
  t[13].b = -0.9 * t[13].a;  // the ring-little spread sees the angle between the two fingers
  return t;
}

std::array<double, kGloveJoints> deg(std::initializer_list<std::pair<int, double>> set) {
  std::array<double, kGloveJoints> a{};
  for (const auto& [j, d] : set) {
    a[static_cast<std::size_t>(j)] = d * kRad;
  }
  return a;
}

// The procedure of docs/glove-calibration.md: flat, fist, spread, thumb opposition and known
// poses that move each sensor's joint apart from its coupled joint.
std::vector<GloveProcedurePose> procedure_poses() {
  return {
      {"flat", 0, 0, deg({})},
      {"fist", 0, 0,
       deg({{0, 20},
            {1, 40},
            {2, 50},
            {4, 90},
            {5, 100},
            {7, 90},
            {8, 100},
            {10, 90},
            {11, 100},
            {13, 90},
            {14, 100}})},
      {"spread", 0, 0, deg({{0, 35}, {3, 15}, {9, -15}, {12, -30}})},
      {"thumb_opposition", 0, 0, deg({{0, 60}, {1, 30}, {2, 30}})},
      {"tabletop", 0, 0, deg({{1, 20}, {4, 90}, {7, 90}, {10, 90}, {13, 90}})},
      {"hook", 0, 0, deg({{2, 60}, {5, 90}, {8, 90}, {11, 90}, {14, 90}})},
      {"little_out", 0, 0, deg({{1, 50}, {12, -25}, {3, 10}, {4, 45}, {10, 45}})},
  };
}

struct Synthetic {
  Trajectory raw;
  GloveProcedure procedure;
};

// Each pose held 1 s at 50 Hz after a 0.5 s move from the previous one (rows in no window);
// counts with Gaussian noise of `sigma` counts, rounded to integers as an ADC reports them.
Synthetic synthesize(const std::array<TrueSensor, kGloveSensors>& glove, double sigma,
                     unsigned seed, std::vector<GloveProcedurePose> poses = procedure_poses()) {
  std::mt19937 rng(seed);
  std::normal_distribution<double> noise(0.0, sigma);
  Synthetic out;
  std::vector<DeviceInput> samples;
  std::vector<double> counts;
  double t = 0.0;
  std::array<double, kGloveJoints> previous{};
  const auto emit = [&](const std::array<double, kGloveJoints>& angles) {
    DeviceInput s;
    s.time_s = t;
    s.p_world = Vec3(0.1, 0.0, 0.2);
    samples.push_back(s);
    for (int k = 0; k < kGloveSensors; ++k) {
      const GloveSensorSpec& spec = glove_sensor_layout()[static_cast<std::size_t>(k)];
      const TrueSensor& g = glove[static_cast<std::size_t>(k)];
      double c = g.offset + g.a * angles[static_cast<std::size_t>(spec.joint)];
      if (spec.coupled_joint >= 0) {
        c += g.b * angles[static_cast<std::size_t>(spec.coupled_joint)];
      }
      counts.push_back(std::round(c + noise(rng)));
    }
    t += 0.02;
  };
  for (GloveProcedurePose& pose : poses) {
    for (int k = 1; k <= 25; ++k) {  // the move: not held
      std::array<double, kGloveJoints> a{};
      for (int j = 0; j < kGloveJoints; ++j) {
        a[static_cast<std::size_t>(j)] =
            previous[static_cast<std::size_t>(j)] +
            (pose.angles_rad[static_cast<std::size_t>(j)] - previous[static_cast<std::size_t>(j)]) *
                k / 25.0;
      }
      emit(a);
    }
    pose.from_s = t - 1e-9;
    for (int k = 0; k < 50; ++k) {
      emit(pose.angles_rad);
    }
    pose.to_s = t - 0.02 + 1e-9;
    previous = pose.angles_rad;
  }
  out.raw = make_trajectory(std::move(samples), 0, 0, "synthetic");
  out.raw.sensor_count = kGloveSensors;
  out.raw.sensor_counts = std::move(counts);
  out.procedure.poses = std::move(poses);
  return out;
}

std::string refusal(const Synthetic& s, const GloveFitOptions& options = {}) {
  try {
    (void)fit_glove_calibration(s.raw, s.procedure, options, "raw.csv");
  } catch (const Error& e) {
    return e.what();
  }
  return "(not refused)";
}

TEST(GloveCalibration, RecoversKnownGainsOffsetsAndCouplingsWithinFiveStandardErrors) {
  const auto glove = true_glove();
  const double sigma = 1.0;
  const Synthetic s = synthesize(glove, sigma, 7);
  const GloveCalibration c = fit_glove_calibration(s.raw, s.procedure, {}, "raw.csv");
  // Noise 1 count plus rounding (uniform, variance 1/12).
  const double sigma_eff = std::sqrt(sigma * sigma + 1.0 / 12.0);
  double worst_in_se = 0.0;
  for (int k = 0; k < kGloveSensors; ++k) {
    const GloveSensorSpec& spec = glove_sensor_layout()[static_cast<std::size_t>(k)];
    const bool coupled = spec.coupled_joint >= 0;
    // The design the fit sees: one row per held sample, [1, θ_joint, θ_coupled].
    std::vector<std::array<double, 3>> rows;
    for (const GloveProcedurePose& p : s.procedure.poses) {
      for (int n = 0; n < 50; ++n) {
        rows.push_back(
            {1.0, p.angles_rad[static_cast<std::size_t>(spec.joint)],
             coupled ? p.angles_rad[static_cast<std::size_t>(spec.coupled_joint)] : 0.0});
      }
    }
    const int cols = coupled ? 3 : 2;
    Eigen::MatrixXd X(static_cast<Eigen::Index>(rows.size()), cols);
    for (std::size_t r = 0; r < rows.size(); ++r) {
      for (int c2 = 0; c2 < cols; ++c2) {
        X(static_cast<Eigen::Index>(r), c2) = rows[r][static_cast<std::size_t>(c2)];
      }
    }
    const Eigen::MatrixXd cov = sigma_eff * sigma_eff * (X.transpose() * X).inverse();
    const TrueSensor& want = glove[static_cast<std::size_t>(k)];
    const GloveSensorFit& got = c.sensors[static_cast<std::size_t>(k)];
    const double a = 1.0 / got.gain_rad_per_count;
    const double b = got.coupling * a;
    const auto check = [&](const char* what, double estimate, double truth, double variance) {
      const double se = std::sqrt(variance);
      EXPECT_LE(std::abs(estimate - truth), 5.0 * se)
          << glove_sensor_label(k) << " " << what << ": " << estimate << " vs " << truth
          << " (standard error " << se << ")";
      worst_in_se = std::max(worst_in_se, std::abs(estimate - truth) / se);
    };
    check("offset", got.offset_counts, want.offset, cov(0, 0));
    check("counts per rad", a, want.a, cov(1, 1));
    if (coupled) {
      check("coupling counts per rad", b, want.b, cov(2, 2));
    }
  }
  std::printf("worst parameter error: %.2f standard errors\n", worst_in_se);
  // The residuals are the counts' noise through the inverse: per joint σ·|row of M|, within
  // ±25 % over the ~350 held samples (the fit's own parameter error adds a little).
  ASSERT_EQ(c.residuals.size(), static_cast<std::size_t>(kGloveJoints - 1));
  for (const GloveJointResidual& r : c.residuals) {
    int row = -1;
    for (int k = 0; k < kGloveSensors; ++k) {
      if (glove_sensor_layout()[static_cast<std::size_t>(k)].joint == r.joint) {
        row = k;
      }
    }
    ASSERT_GE(row, 0);
    const double predicted_deg = sigma_eff * c.rad_per_count.row(row).norm() / kRad;
    EXPECT_NEAR(r.rms_deg, predicted_deg, 0.25 * predicted_deg) << glove_joint_label(r.joint);
    EXPECT_LT(r.rms_deg, 2.0);
    std::printf("%-20s residual %.3f deg RMS (predicted %.3f), max %.3f\n",
                glove_joint_label(r.joint).c_str(), r.rms_deg, predicted_deg, r.max_deg);
  }
}

TEST(GloveCalibration, RefusesADeadSensorNamingIt) {
  auto glove = true_glove();
  glove[7].a = 0.0;  // ring MCP: stuck at its offset, only noise
  glove[7].b = 0.0;
  const Synthetic s = synthesize(glove, 0.3, 11);
  const std::string e = refusal(s);
  EXPECT_NE(e.find("raw.csv"), std::string::npos) << e;
  EXPECT_NE(e.find("sensor s7 (ring MCP flexion) never moved"), std::string::npos) << e;
}

TEST(GloveCalibration, RefusesASensorThatMovesButNotWithItsJoint) {
  auto glove = true_glove();
  glove[4].a = 0.01;  // index PIP reads noise of 4 counts, not the joint
  const Synthetic s = synthesize(glove, 4.0, 3);
  const std::string e = refusal(s);
  EXPECT_NE(e.find("sensor s4 (index PIP flexion) does not follow j5 (index PIP)"),
            std::string::npos)
      << e;
}

TEST(GloveCalibration, RefusesAJointWhoseResidualExceedsTheThreshold) {
  // The user let the middle PIP drift during the fist: its sensor reads 40° less half the time.
  const auto glove = true_glove();
  Synthetic s = synthesize(glove, 1.0, 5);
  const GloveProcedurePose& fist = s.procedure.poses[1];
  std::size_t drifted = 0;
  for (std::size_t i = 0; i < s.raw.size(); ++i) {
    const double t = s.raw.samples[i].time_s;
    if (t >= fist.from_s && t <= fist.to_s && (drifted++ % 2) == 0) {
      s.raw.sensor_counts[i * kGloveSensors + 6] -= glove[6].a * 40.0 * kRad;
    }
  }
  const std::string e = refusal(s);
  EXPECT_NE(e.find("joint j8 (middle PIP) (sensor s6 (middle PIP flexion)) fits badly"),
            std::string::npos)
      << e;
  // With a lax threshold the same data passes, and reports the residual it refused.
  GloveFitOptions lax;
  lax.max_residual_deg = 30.0;
  const GloveCalibration c = fit_glove_calibration(s.raw, s.procedure, lax, "raw.csv");
  for (const GloveJointResidual& r : c.residuals) {
    if (r.joint == 8) {
      EXPECT_GT(r.rms_deg, 5.0);
    }
  }
}

TEST(GloveCalibration, RefusesAMissingPoseAndPosesThatCannotSeparateTwoJoints) {
  Synthetic s = synthesize(true_glove(), 1.0, 9);
  Synthetic late = s;
  late.procedure.poses[2].from_s = 1000.0;
  late.procedure.poses[2].to_s = 1001.0;
  EXPECT_NE(refusal(late).find("pose 'spread' is missing: no rows between 1000 and 1001 s"),
            std::string::npos)
      << refusal(late);
  // Without "little_out" the ring's and the little finger's spread move together.
  std::vector<GloveProcedurePose> poses = procedure_poses();
  poses.pop_back();
  const Synthetic together = synthesize(true_glove(), 1.0, 9, poses);
  EXPECT_NE(refusal(together).find("sensor s13 (ring-little spread) cannot be fitted: the poses "
                                   "move j12 (little abduction) and j9 (ring abduction) together"),
            std::string::npos)
      << refusal(together);
  Synthetic middle = s;
  middle.procedure.poses[1].angles_rad[kGloveUnmeasuredJoint] = 0.1;
  EXPECT_NE(refusal(middle).find("pose 'fist' sets j6 (middle abduction)"), std::string::npos)
      << refusal(middle);
  Synthetic wrong_count = s;
  wrong_count.raw.sensor_count = 13;
  EXPECT_NE(refusal(wrong_count).find("has 13 sensor columns; expected s0..s13"),
            std::string::npos);
}

TEST(GloveCalibration, PivotFindsTheHandOriginInTheTrackerFrame) {
  Synthetic s = synthesize(true_glove(), 1.0, 13);
  // After the poses: 4 s rocking about a fixed point with the hand origin on it, 0.3 mm noise.
  const Vec3 r_true(-0.02, 0.015, -0.035);
  const Vec3 x_world(0.3, -0.1, 0.05);
  std::mt19937 rng(2);
  std::normal_distribution<double> noise(0.0, 3e-4);
  std::vector<DeviceInput> samples = s.raw.samples;
  std::vector<double> counts = s.raw.sensor_counts;
  const double t0 = samples.back().time_s + 0.02;
  for (int k = 0; k < 200; ++k) {
    const double u = k / 200.0;
    const Quat q =
        Quat(Eigen::AngleAxisd(0.5 * std::sin(2 * std::numbers::pi * u), Vec3::UnitX())) *
        Quat(Eigen::AngleAxisd(0.4 * std::sin(4 * std::numbers::pi * u), Vec3::UnitY()));
    DeviceInput d;
    d.time_s = t0 + 0.02 * k;
    d.q_world = q;
    d.p_world = x_world - q * r_true + Vec3(noise(rng), noise(rng), noise(rng));
    samples.push_back(d);
    for (int c = 0; c < kGloveSensors; ++c) {
      counts.push_back(counts[static_cast<std::size_t>(c)]);  // the flat hand's first reading
    }
  }
  s.raw = make_trajectory(std::move(samples), 0, 0, "synthetic");
  s.raw.sensor_count = kGloveSensors;
  s.raw.sensor_counts = std::move(counts);
  s.procedure.has_pivot = true;
  s.procedure.pivot_from_s = t0;
  s.procedure.pivot_to_s = t0 + 4.0;
  const GloveCalibration c = fit_glove_calibration(s.raw, s.procedure, {}, "raw.csv");
  EXPECT_TRUE(c.palm_offset_fitted);
  // 200 rows of 0.3 mm noise: the point is known to ~0.05 mm; 0.5 mm is a tenth of the threshold.
  EXPECT_LT((c.p_tracker_hand - r_true).norm(), 5e-4);
  EXPECT_NEAR(c.pivot_rms_m, 3e-4 * std::sqrt(3.0), 1e-4);
  // A window where the hand only slides is refused: it hardly turns.
  s.procedure.pivot_from_s = 0.0;
  s.procedure.pivot_to_s = 1.0;
  EXPECT_NE(refusal(s).find("pivot: the tracker turned only 0.0 deg"), std::string::npos)
      << refusal(s);
}

TEST(GloveCalibration, RawTrajectoryGivesTheAnglesItWasMadeFrom) {
  const auto glove = true_glove();
  const GloveCalibration c = fit_glove_calibration(
      synthesize(glove, 1.0, 17).raw, synthesize(glove, 1.0, 17).procedure, {}, "raw.csv");
  // An angle trajectory (a slow grasp with spread) and its raw version: integer counts, no noise.
  std::vector<DeviceInput> samples;
  std::vector<double> counts;
  std::vector<std::array<double, kGloveJoints>> truth;
  for (int k = 0; k <= 100; ++k) {
    const double u = k / 100.0;
    auto a = deg({{0, 30 * u},
                  {1, 35 * u},
                  {2, 40 * u},
                  {3, 10 * u},
                  {4, 70 * u},
                  {5, 80 * u},
                  {7, 60 * u},
                  {8, 70 * u},
                  {9, -8 * u},
                  {10, 50 * u},
                  {11, 60 * u},
                  {12, -15 * u},
                  {13, 40 * u},
                  {14, 50 * u}});
    truth.push_back(a);
    DeviceInput d;
    d.time_s = 0.01 * k;
    d.p_world = Vec3(0.0, 0.1 * u, 0.2);
    d.q_world = Quat(Eigen::AngleAxisd(u, Vec3::UnitZ()));
    samples.push_back(d);
    for (int s = 0; s < kGloveSensors; ++s) {
      const GloveSensorSpec& spec = glove_sensor_layout()[static_cast<std::size_t>(s)];
      const TrueSensor& g = glove[static_cast<std::size_t>(s)];
      double v = g.offset + g.a * a[static_cast<std::size_t>(spec.joint)];
      if (spec.coupled_joint >= 0) {
        v += g.b * a[static_cast<std::size_t>(spec.coupled_joint)];
      }
      counts.push_back(std::round(v));
    }
  }
  Trajectory raw = make_trajectory(samples, 0, 0, "raw");
  raw.sensor_count = kGloveSensors;
  raw.sensor_counts = counts;
  GloveCalibration offset = c;
  offset.p_tracker_hand = Vec3(-0.03, 0.01, -0.02);
  const Trajectory angles = calibrated_glove_trajectory(raw, offset, "raw.csv");
  ASSERT_EQ(angles.joint_count, kGloveJoints);
  // Rounding to whole counts (±0.5 count, ~0.5° at 60 counts/rad) and the fit's error from 1 count
  // of noise: within 1° of the angles the counts were made from.
  double worst_deg = 0.0;
  for (std::size_t i = 0; i < angles.size(); ++i) {
    for (int j = 0; j < kGloveJoints; ++j) {
      const double e = std::abs(angles.samples[i].joint_rad[static_cast<std::size_t>(j)] -
                                truth[i][static_cast<std::size_t>(j)]) /
                       kRad;
      worst_deg = std::max(worst_deg, e);
    }
    EXPECT_EQ(angles.samples[i].joint_rad[kGloveUnmeasuredJoint], 0.0);
    // The hand's pose: the tracker's, moved by the tracker-to-hand offset.
    const Vec3 want = samples[i].p_world + samples[i].q_world * offset.p_tracker_hand;
    EXPECT_LT((angles.samples[i].p_world - want).norm(), 1e-12);
    EXPECT_LT(angles.samples[i].q_world.angularDistance(samples[i].q_world), 1e-9);
  }
  EXPECT_LT(worst_deg, 1.0);
  std::printf("raw → angles: worst joint error %.3f deg\n", worst_deg);
}

}  // namespace
}  // namespace hapsim
