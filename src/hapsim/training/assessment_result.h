// What the assessment of one session found (docs/assessment.md; the JSON is
// assessment_json.h's, schema "hapsim.assessment/1"). Times are seconds from the session's
// first cycle; forces newtons; points world frame, metres.
#pragma once

#include "hapsim/core/types.h"

#include <map>
#include <optional>
#include <string>
#include <vector>

namespace hapsim {

struct LandmarkResult {
  std::string name;
  std::string segment;
  std::optional<Vec3> point_world;
  double radius_m = 0.0;
  double required_force_n = 0.0;
  double required_dwell_s = 0.0;
  bool found = false;
  double found_at_s = 0.0;        ///< when the dwell completed (found only)
  double force_at_found_n = 0.0;  ///< (found only)
  double dwell_s = 0.0;           ///< longest continuous time at or above the force
  double contact_s = 0.0;         ///< total time touching it at any force
  bool touched = false;
  double mean_force_n = 0.0;  ///< over the cycles touching it (touched only)
  double peak_force_n = 0.0;
  /// Where it was pressed hardest (its strongest contact at the peak; touched only).
  Vec3 peak_point_world = Vec3::Zero();
};

/// One continuous spell of a tissue's force above its limit.
struct BreachResult {
  std::string tissue;
  double start_s = 0.0;
  double duration_s = 0.0;
  double peak_force_n = 0.0;
  double excess_n = 0.0;  ///< peak − limit
  double peak_at_s = 0.0;
  Vec3 point_world = Vec3::Zero();  ///< where the peak was (its strongest contact)
};

struct LimitResult {
  std::string tissue;
  double max_force_n = 0.0;
  std::size_t breaches = 0;
  double breach_duration_s = 0.0;
  double worst_excess_n = 0.0;
  double worst_at_s = 0.0;
  Vec3 worst_point_world = Vec3::Zero();
};

/// A teleoperation pick-and-place (docs/assessment.md, "Pick and place").
struct TeleopAssessment {
  std::optional<double> time_to_grasp_s;  ///< none: never grasped
  std::size_t drops = 0;
  std::optional<double> placement_error_m;  ///< the ball's final distance from the target
  double peak_grasp_force_n = 0.0;
  std::size_t collisions = 0;
  bool placed = false;
};

struct AssessmentScore {
  double value = 0.0;
  double max = 100.0;
  std::string formula;
  /// Named contributions in the order they are summed (value = max(0, Σ terms)).
  std::vector<std::pair<std::string, double>> terms;
};

struct AssessmentResult {
  std::string kind = "palpation";  ///< or "pick_and_place"
  double duration_s = 0.0;
  std::optional<double> time_limit_s;
  bool over_time = false;
  double path_length_m = 0.0;
  double mean_force_n = 0.0;  ///< over cycles in contact
  double peak_force_n = 0.0;
  std::vector<LandmarkResult> landmarks;
  std::vector<LimitResult> limits;
  std::vector<BreachResult> breaches;
  std::optional<TeleopAssessment> teleop;
  AssessmentScore score;
  /// The force time series: column names ("t_s", "total_force_n", tissues...) and one row per
  /// 10 ms bin holding each column's maximum over the bin (t_s: the bin's start).
  std::vector<std::string> force_columns;
  std::vector<std::vector<double>> force_rows;

  [[nodiscard]] std::size_t landmarks_found() const;
};

}  // namespace hapsim
