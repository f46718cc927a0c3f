// Glove calibration (issue 16; knee paper 001 §3.1: the DataGlove's driver turns raw sensor
// readings into joint angles "based on user calibration"): a per-user linear model of each raw
// sensor (sensor layout: glove_sensor_layout.h), fitted by least squares to a short recorded
// procedure of known poses, plus the tracker-to-hand offset. docs/glove-calibration.md.
//
// The model is the sensor's forward response, fitted per sensor with the poses' known angles as
// regressors (exact) and the counts as the response (noisy), so ordinary least squares is
// unbiased — fitting angles from counts would put the noise in the regressors and shrink the
// gains (errors-in-variables):
//
//   counts_s = offset_s + (θ_joint(s) + coupling_s · θ_coupled(s)) / gain_s
//
// Calibrated angles are the exact inverse, θ = M·(counts − offset) over all sensors at once
// (M the inverse of the 14×14 response matrix), computed when a calibration is made or loaded,
// never on the haptic path: a raw trajectory is converted when it is loaded.
#pragma once

#include "hapsim/core/types.h"
#include "hapsim/device/glove_sensor_layout.h"
#include "hapsim/script/trajectory.h"

#include <Eigen/Dense>

#include <array>
#include <cstddef>
#include <span>
#include <string>
#include <string_view>
#include <vector>

namespace hapsim {

/// One pose of the procedure: the angles the user holds (j0..j14, radians; j6 must be 0) and
/// when, in the raw recording's time (rows with from_s <= t <= to_s).
struct GloveProcedurePose {
  std::string name;
  double from_s = 0.0;
  double to_s = 0.0;
  std::array<double, kGloveJoints> angles_rad{};
};

struct GloveProcedure {
  std::vector<GloveProcedurePose> poses;
  /// Pivot calibration of the tracker-to-hand offset: between these times the user keeps the
  /// hand frame's origin (the heel of the palm, hand_model.h) on one fixed point and rocks the
  /// hand about it. Without it, p_tracker_hand is taken as given.
  bool has_pivot = false;
  double pivot_from_s = 0.0;
  double pivot_to_s = 0.0;
  /// The hand frame in the tracker frame: the origin when given (no pivot), and the rotation
  /// (always given: a pivot fixes a point, not a direction).
  Vec3 p_tracker_hand = Vec3::Zero();
  Quat q_tracker_hand = Quat::Identity();
};

struct GloveFitOptions {
  /// A sensor whose counts span less than this over the whole recording never moved (dead).
  double min_sensor_range_counts = 8.0;
  /// A joint whose calibrated angles miss the poses' by more than this (RMS) is refused.
  double max_residual_deg = 5.0;
  /// The pivot point's RMS scatter above this refuses the pivot fit, metres.
  double max_pivot_rms_m = 0.005;
  /// The tracker must turn at least this far during the pivot, degrees.
  double min_pivot_rotation_deg = 20.0;
};

/// One sensor's fitted response (the model above).
struct GloveSensorFit {
  int joint = 0;
  int coupled_joint = -1;
  double offset_counts = 0.0;
  double gain_rad_per_count = 0.0;
  double coupling = 0.0;
  /// Counts spanned over the recording (for the report).
  double range_counts = 0.0;
};

struct GloveJointResidual {
  int joint = 0;
  int sensor = 0;  // the sensor that reads it
  double rms_deg = 0.0;
  double max_deg = 0.0;
};

struct GloveCalibration {
  std::string layout{kGloveLayoutName};
  std::array<GloveSensorFit, kGloveSensors> sensors{};
  /// The hand frame in the tracker frame (X_tracker_hand).
  Vec3 p_tracker_hand = Vec3::Zero();
  Quat q_tracker_hand = Quat::Identity();
  bool palm_offset_fitted = false;
  double pivot_rms_m = 0.0;
  std::size_t pivot_samples = 0;
  /// Per measured joint, over every held sample of the procedure (empty when loaded from a file
  /// that lists none).
  std::vector<GloveJointResidual> residuals;
  std::size_t held_samples = 0;
  /// θ_measured = rad_per_count · (counts − offset), row k the angle of sensor k's joint;
  /// set by finish_glove_calibration().
  Eigen::Matrix<double, kGloveSensors, kGloveSensors> rad_per_count =
      Eigen::Matrix<double, kGloveSensors, kGloveSensors>::Zero();
};

/// Fits the calibration to a raw recording (columns s0..s13, every row) and its procedure.
/// Throws hapsim::Error at `raw_name` (or the pose) naming the sensor or joint: a wrong sensor
/// count, a pose with no rows in its window, a pose that sets j6, a dead sensor (counts span
/// < min_sensor_range_counts), a joint the poses never move or move only together with the
/// sensor's coupled joint, a sensor that does not follow its joint, a joint whose RMS residual
/// exceeds max_residual_deg, a pivot that hardly turns or scatters.
[[nodiscard]] GloveCalibration fit_glove_calibration(const Trajectory& raw,
                                                     const GloveProcedure& procedure,
                                                     const GloveFitOptions& options,
                                                     std::string_view raw_name);

/// Computes rad_per_count from the sensors' fits (after loading one from a file). Throws
/// hapsim::Error at `where` when a gain is zero or not finite or the response matrix is singular.
void finish_glove_calibration(GloveCalibration& calibration, std::string_view where);

/// The hand model's angles j0..j14 (radians) for one reading of kGloveSensors counts; j6 = 0.
[[nodiscard]] std::array<double, kGloveJoints> glove_joint_angles(
    const GloveCalibration& calibration, std::span<const double> counts) noexcept;

/// The hand's pose for the tracker's pose: X_world_tracker · X_tracker_hand.
[[nodiscard]] Iso3 glove_hand_pose(const GloveCalibration& calibration,
                                   const Iso3& X_world_tracker) noexcept;

/// A raw trajectory (pose of the tracker, s0..s13) as the glove trajectory it stands for: the
/// hand's pose and j0..j14. Throws hapsim::Error at `where` when it has not kGloveSensors
/// sensor columns.
[[nodiscard]] Trajectory calibrated_glove_trajectory(const Trajectory& raw,
                                                     const GloveCalibration& calibration,
                                                     std::string_view where);

}  // namespace hapsim
