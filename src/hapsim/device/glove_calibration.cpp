#include "hapsim/device/glove_calibration.h"

#include "hapsim/core/error.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <numbers>

namespace hapsim {
namespace {

constexpr double kDegPerRad = 180.0 / std::numbers::pi;

std::string number_text(const char* format, double value) {
  char buf[64];
  std::snprintf(buf, sizeof buf, format, value);
  return buf;
}

// The sensor whose own joint is `joint`, or -1 (the unmeasured middle abduction).
int sensor_of_joint(int joint) {
  const auto& layout = glove_sensor_layout();
  for (int s = 0; s < kGloveSensors; ++s) {
    if (layout[static_cast<std::size_t>(s)].joint == joint) {
      return s;
    }
  }
  return -1;
}

// One held sample: the row of the recording and the pose it holds.
struct HeldSample {
  std::size_t row = 0;
  std::size_t pose = 0;
};

// The tracker-to-hand origin by pivot calibration: R_i·r + p_i = x for every row (r the origin in
// the tracker frame, x the fixed point in the world), linear least squares in (r, x).
void fit_pivot(const Trajectory& raw, const GloveProcedure& procedure,
               const GloveFitOptions& options, std::string_view raw_name, GloveCalibration& out) {
  const std::string where = std::string(raw_name) + ": pivot";
  std::vector<std::size_t> rows;
  for (std::size_t i = 0; i < raw.size(); ++i) {
    const double t = raw.samples[i].time_s;
    if (t >= procedure.pivot_from_s && t <= procedure.pivot_to_s) {
      rows.push_back(i);
    }
  }
  if (rows.size() < 3) {
    throw Error(where, "only " + std::to_string(rows.size()) + " row(s) between " +
                           number_text("%g", procedure.pivot_from_s) + " and " +
                           number_text("%g", procedure.pivot_to_s) + " s; expected at least 3");
  }
  double max_turn_rad = 0.0;
  const Quat& q0 = raw.samples[rows.front()].q_world;
  for (const std::size_t i : rows) {
    max_turn_rad = std::max(max_turn_rad, q0.angularDistance(raw.samples[i].q_world));
  }
  if (max_turn_rad * kDegPerRad < options.min_pivot_rotation_deg) {
    throw Error(where, "the tracker turned only " + number_text("%.1f", max_turn_rad * kDegPerRad) +
                           " deg about the pivot; expected at least " +
                           number_text("%g", options.min_pivot_rotation_deg) +
                           " deg (rock the hand about the point in two directions)");
  }
  Eigen::MatrixXd A(3 * rows.size(), 6);
  Eigen::VectorXd b(3 * rows.size());
  for (std::size_t k = 0; k < rows.size(); ++k) {
    const DeviceInput& s = raw.samples[rows[k]];
    const auto r = static_cast<Eigen::Index>(3 * k);
    A.block<3, 3>(r, 0) = s.q_world.toRotationMatrix();
    A.block<3, 3>(r, 3) = -Mat3::Identity();
    b.segment<3>(r) = -s.p_world;
  }
  const Eigen::JacobiSVD<Eigen::MatrixXd> svd(A, Eigen::ComputeThinU | Eigen::ComputeThinV);
  const Eigen::VectorXd& sv = svd.singularValues();
  if (!(sv(5) > 1e-3 * sv(0))) {
    throw Error(where,
                "the tracker turned about one axis only: the point along it is not "
                "fixed; rock the hand about the point in two directions");
  }
  const Eigen::VectorXd sol = svd.solve(b);
  const Eigen::VectorXd res = A * sol - b;
  out.pivot_rms_m = std::sqrt(res.squaredNorm() / static_cast<double>(rows.size()));
  out.pivot_samples = rows.size();
  if (!(out.pivot_rms_m <= options.max_pivot_rms_m)) {
    throw Error(where, "the pivot point scatters by " + number_text("%.1f", out.pivot_rms_m * 1e3) +
                           " mm RMS; expected at most " +
                           number_text("%.1f", options.max_pivot_rms_m * 1e3) +
                           " mm (the hand slid on the point, or the window holds other motion)");
  }
  out.p_tracker_hand = sol.head<3>();
  out.palm_offset_fitted = true;
}

}  // namespace

void finish_glove_calibration(GloveCalibration& c, std::string_view where) {
  // Response matrix: counts − offset = A·θ_measured (column k is sensor k's own joint).
  Eigen::Matrix<double, kGloveSensors, kGloveSensors> A =
      Eigen::Matrix<double, kGloveSensors, kGloveSensors>::Zero();
  for (int s = 0; s < kGloveSensors; ++s) {
    const GloveSensorFit& f = c.sensors[static_cast<std::size_t>(s)];
    if (!std::isfinite(f.gain_rad_per_count) || f.gain_rad_per_count == 0.0 ||
        !std::isfinite(f.coupling) || !std::isfinite(f.offset_counts)) {
      throw Error(std::string(where), "sensor " + glove_sensor_label(s) +
                                          ": expected a finite, non-zero gain and finite offset "
                                          "and coupling");
    }
    const double counts_per_rad = 1.0 / f.gain_rad_per_count;
    A(s, s) = counts_per_rad;
    if (f.coupled_joint >= 0) {
      A(s, sensor_of_joint(f.coupled_joint)) += f.coupling * counts_per_rad;
    }
  }
  const Eigen::FullPivLU<Eigen::Matrix<double, kGloveSensors, kGloveSensors>> lu(A);
  if (!lu.isInvertible()) {
    throw Error(std::string(where),
                "the sensors' responses are singular: the couplings make "
                "two sensors read the same combination of joints");
  }
  c.rad_per_count = lu.inverse();
}

std::array<double, kGloveJoints> glove_joint_angles(const GloveCalibration& c,
                                                    std::span<const double> counts) noexcept {
  Eigen::Matrix<double, kGloveSensors, 1> d;
  for (int s = 0; s < kGloveSensors; ++s) {
    const auto i = static_cast<std::size_t>(s);
    d(s) =
        (i < counts.size() ? counts[i] : c.sensors[i].offset_counts) - c.sensors[i].offset_counts;
  }
  const Eigen::Matrix<double, kGloveSensors, 1> theta = c.rad_per_count * d;
  std::array<double, kGloveJoints> angles{};
  for (int s = 0; s < kGloveSensors; ++s) {
    angles[static_cast<std::size_t>(glove_sensor_layout()[static_cast<std::size_t>(s)].joint)] =
        theta(s);
  }
  return angles;  // kGloveUnmeasuredJoint stays 0
}

Iso3 glove_hand_pose(const GloveCalibration& c, const Iso3& X_world_tracker) noexcept {
  Iso3 X_tracker_hand = Iso3::Identity();
  X_tracker_hand.linear() = c.q_tracker_hand.toRotationMatrix();
  X_tracker_hand.translation() = c.p_tracker_hand;
  return X_world_tracker * X_tracker_hand;
}

GloveCalibration fit_glove_calibration(const Trajectory& raw, const GloveProcedure& procedure,
                                       const GloveFitOptions& options, std::string_view raw_name) {
  const std::string file(raw_name);
  const auto& layout = glove_sensor_layout();
  if (raw.sensor_count != kGloveSensors) {
    throw Error(file, "has " + std::to_string(raw.sensor_count) +
                          " sensor columns; expected s0..s" + std::to_string(kGloveSensors - 1) +
                          " (layout " + std::string(kGloveLayoutName) + ")");
  }
  if (procedure.poses.empty()) {
    throw Error(file, "the procedure has no poses");
  }
  // Held samples, per pose.
  std::vector<HeldSample> held;
  for (std::size_t p = 0; p < procedure.poses.size(); ++p) {
    const GloveProcedurePose& pose = procedure.poses[p];
    if (pose.angles_rad[kGloveUnmeasuredJoint] != 0.0) {
      throw Error(file, "pose '" + pose.name + "' sets " +
                            glove_joint_label(kGloveUnmeasuredJoint) +
                            ", which no sensor reads (the spread sensors measure from the middle "
                            "finger); expected 0");
    }
    std::size_t n = 0;
    for (std::size_t i = 0; i < raw.size(); ++i) {
      const double t = raw.samples[i].time_s;
      if (t >= pose.from_s && t <= pose.to_s) {
        held.push_back({i, p});
        ++n;
      }
    }
    if (n == 0) {
      throw Error(file, "pose '" + pose.name + "' is missing: no rows between " +
                            number_text("%g", pose.from_s) + " and " +
                            number_text("%g", pose.to_s) + " s");
    }
  }
  GloveCalibration out;
  out.held_samples = held.size();
  // Dead sensors: over the whole recording.
  for (int s = 0; s < kGloveSensors; ++s) {
    double lo = raw.sensors(0)[static_cast<std::size_t>(s)];
    double hi = lo;
    for (std::size_t i = 0; i < raw.size(); ++i) {
      const double c = raw.sensors(i)[static_cast<std::size_t>(s)];
      lo = std::min(lo, c);
      hi = std::max(hi, c);
    }
    out.sensors[static_cast<std::size_t>(s)].range_counts = hi - lo;
    if (!(hi - lo >= options.min_sensor_range_counts)) {
      throw Error(file, "sensor " + glove_sensor_label(s) + " never moved: its counts stay in [" +
                            number_text("%g", lo) + ", " + number_text("%g", hi) +
                            "] over the recording (span " + number_text("%g", hi - lo) + " < " +
                            number_text("%g", options.min_sensor_range_counts) +
                            " counts); check its connection");
    }
  }
  // Per sensor: counts = o + a·θ_joint + b·θ_coupled, ordinary least squares.
  for (int s = 0; s < kGloveSensors; ++s) {
    const GloveSensorSpec& spec = layout[static_cast<std::size_t>(s)];
    const bool coupled = spec.coupled_joint >= 0;
    const Eigen::Index cols = coupled ? 3 : 2;
    Eigen::MatrixXd X(static_cast<Eigen::Index>(held.size()), cols);
    Eigen::VectorXd y(static_cast<Eigen::Index>(held.size()));
    for (std::size_t k = 0; k < held.size(); ++k) {
      const auto& angles = procedure.poses[held[k].pose].angles_rad;
      const auto r = static_cast<Eigen::Index>(k);
      X(r, 0) = 1.0;
      X(r, 1) = angles[static_cast<std::size_t>(spec.joint)];
      if (coupled) {
        X(r, 2) = angles[static_cast<std::size_t>(spec.coupled_joint)];
      }
      y(r) = raw.sensors(held[k].row)[static_cast<std::size_t>(s)];
    }
    // Identifiable? The joint must move across the poses, and apart from the coupled joint.
    const Eigen::VectorXd joint_col = X.col(1).array() - X.col(1).mean();
    const double joint_span_rad = X.col(1).maxCoeff() - X.col(1).minCoeff();
    if (!(joint_span_rad * kDegPerRad >= 5.0)) {
      throw Error(file, "sensor " + glove_sensor_label(s) + " cannot be fitted: the poses hold " +
                            glove_joint_label(spec.joint) + " within " +
                            number_text("%.1f", joint_span_rad * kDegPerRad) +
                            " deg; add a pose that moves it");
    }
    if (coupled) {
      const Eigen::VectorXd other = X.col(2).array() - X.col(2).mean();
      const double denom = joint_col.norm() * other.norm();
      const double corr = denom > 0.0 ? joint_col.dot(other) / denom : 0.0;
      if (std::abs(corr) > 0.98) {
        throw Error(file, "sensor " + glove_sensor_label(s) + " cannot be fitted: the poses move " +
                              glove_joint_label(spec.joint) + " and " +
                              glove_joint_label(spec.coupled_joint) + " together (correlation " +
                              number_text("%.3f", corr) +
                              "); add a pose that moves one without the other");
      }
    }
    const Eigen::VectorXd beta = X.colPivHouseholderQr().solve(y);
    const double a = beta(1);
    // A sensor that moved but not with its joint: its own joint's whole span changes it by less
    // than a dead sensor's threshold.
    if (!(std::abs(a) * joint_span_rad >= options.min_sensor_range_counts)) {
      throw Error(file, "sensor " + glove_sensor_label(s) + " does not follow " +
                            glove_joint_label(spec.joint) + ": " +
                            number_text("%.3g", std::abs(a) * joint_span_rad) +
                            " counts over the poses' " +
                            number_text("%.0f", joint_span_rad * kDegPerRad) +
                            " deg of it (its counts move with something else, or it is on the "
                            "wrong finger)");
    }
    GloveSensorFit& fit = out.sensors[static_cast<std::size_t>(s)];
    fit.joint = spec.joint;
    fit.coupled_joint = spec.coupled_joint;
    fit.offset_counts = beta(0);
    fit.gain_rad_per_count = 1.0 / a;
    fit.coupling = coupled ? beta(2) / a : 0.0;
  }
  finish_glove_calibration(out, file);
  // Residuals of the calibrated angles against the poses, per measured joint.
  std::array<double, kGloveJoints> sum_sq{};
  std::array<double, kGloveJoints> max_abs{};
  for (const HeldSample& h : held) {
    const auto angles = glove_joint_angles(out, raw.sensors(h.row));
    const auto& target = procedure.poses[h.pose].angles_rad;
    for (int j = 0; j < kGloveJoints; ++j) {
      const double e =
          (angles[static_cast<std::size_t>(j)] - target[static_cast<std::size_t>(j)]) * kDegPerRad;
      sum_sq[static_cast<std::size_t>(j)] += e * e;
      max_abs[static_cast<std::size_t>(j)] =
          std::max(max_abs[static_cast<std::size_t>(j)], std::abs(e));
    }
  }
  for (int j = 0; j < kGloveJoints; ++j) {
    if (j == kGloveUnmeasuredJoint) {
      continue;
    }
    GloveJointResidual r;
    r.joint = j;
    r.sensor = sensor_of_joint(j);
    r.rms_deg = std::sqrt(sum_sq[static_cast<std::size_t>(j)] / static_cast<double>(held.size()));
    r.max_deg = max_abs[static_cast<std::size_t>(j)];
    out.residuals.push_back(r);
  }
  // The worst joint first in the refusal: it names what to redo.
  const auto worst = std::max_element(out.residuals.begin(), out.residuals.end(),
                                      [](const GloveJointResidual& x, const GloveJointResidual& y) {
                                        return x.rms_deg < y.rms_deg;
                                      });
  if (!(worst->rms_deg <= options.max_residual_deg)) {
    throw Error(file, "joint " + glove_joint_label(worst->joint) + " (sensor " +
                          glove_sensor_label(worst->sensor) + ") fits badly: residual " +
                          number_text("%.2f", worst->rms_deg) + " deg RMS (max " +
                          number_text("%.2f", worst->max_deg) + " deg) over the poses, above " +
                          number_text("%g", options.max_residual_deg) +
                          " deg; the user did not hold the poses, or the sensor is not linear");
  }
  out.q_tracker_hand = procedure.q_tracker_hand;
  if (procedure.has_pivot) {
    fit_pivot(raw, procedure, options, raw_name, out);
  } else {
    out.p_tracker_hand = procedure.p_tracker_hand;
  }
  return out;
}

Trajectory calibrated_glove_trajectory(const Trajectory& raw, const GloveCalibration& c,
                                       std::string_view where) {
  if (raw.sensor_count != kGloveSensors) {
    throw Error(std::string(where), "has " + std::to_string(raw.sensor_count) +
                                        " sensor columns; the calibration's layout " + c.layout +
                                        " has s0..s" + std::to_string(kGloveSensors - 1));
  }
  std::vector<DeviceInput> samples;
  samples.reserve(raw.size());
  for (std::size_t i = 0; i < raw.size(); ++i) {
    DeviceInput s = raw.samples[i];
    Iso3 X_world_tracker = Iso3::Identity();
    X_world_tracker.linear() = s.q_world.toRotationMatrix();
    X_world_tracker.translation() = s.p_world;
    const Iso3 X_world_hand = glove_hand_pose(c, X_world_tracker);
    s.p_world = X_world_hand.translation();
    s.q_world = Quat(X_world_hand.linear());
    if (s.q_world.w() < 0.0) {
      s.q_world.coeffs() = -s.q_world.coeffs();  // one hemisphere: slerp between rows stays short
    }
    const auto angles = glove_joint_angles(c, raw.sensors(i));
    std::copy(angles.begin(), angles.end(), s.joint_rad.begin());
    samples.push_back(s);
  }
  Trajectory out = make_trajectory(std::move(samples), raw.finger_count, kGloveJoints, where);
  out.has_buttons = raw.has_buttons;
  return out;
}

}  // namespace hapsim
