// The score formula (docs/assessment.md, "Score"): kept here in one place with its text.
#include "hapsim/training/assessment_scorer.h"

#include <algorithm>
#include <cmath>

namespace hapsim {
namespace {

constexpr double kPerBreach = 5.0;          // points per breach
constexpr double kPerBreachSecond = 10.0;   // points per second over a limit, × (1 + excess/limit)
constexpr double kPerSecondOverTime = 2.0;  // points per second over the time limit
constexpr double kMaxTimePenalty = 20.0;
constexpr double kPlaced = 50.0;    // pick and place: the ball placed
constexpr double kAccuracy = 50.0;  // × max(0, 1 − error / 20 mm)
constexpr double kAccuracyScaleM = 0.020;
constexpr double kPerDrop = 10.0;
constexpr double kPerCollision = 5.0;

}  // namespace

AssessmentScore assessment_score(const AssessmentResult& r) {
  AssessmentScore s;
  s.max = 100.0;
  double breaches = 0.0;  // stays +0 without a breach
  for (const BreachResult& b : r.breaches) {
    const auto limit = std::find_if(r.limits.begin(), r.limits.end(),
                                    [&b](const LimitResult& l) { return l.tissue == b.tissue; });
    const double limit_n = limit != r.limits.end() && limit->max_force_n > 0.0
                               ? limit->max_force_n
                               : std::max(b.peak_force_n - b.excess_n, 1e-9);
    breaches -= kPerBreach + kPerBreachSecond * b.duration_s * (1.0 + b.excess_n / limit_n);
  }
  double time = 0.0;
  if (r.time_limit_s && r.duration_s > *r.time_limit_s) {
    time = -std::min(kMaxTimePenalty, kPerSecondOverTime * (r.duration_s - *r.time_limit_s));
  }
  const char* common =
      " breaches = -sum over breaches of (5 + 10 * duration_s * (1 + excess_n / max_force_n)): "
      "5 points per breach plus 10 points per second over a tissue's limit, scaled up by how far "
      "over it the peak went. time = -2 points per second beyond time_limit_s, at most -20 (0 "
      "without a limit). value = max(0, sum of the terms), out of 100.";
  if (r.teleop) {
    const TeleopAssessment& t = *r.teleop;
    const double accuracy =
        t.placement_error_m
            ? kAccuracy * std::max(0.0, 1.0 - *t.placement_error_m / kAccuracyScaleM)
            : 0.0;
    s.terms = {{"placed", t.placed ? kPlaced : 0.0},
               {"accuracy", accuracy},
               // + 0.0: no drop is +0 points, not −0.
               {"drops", -kPerDrop * static_cast<double>(t.drops) + 0.0},
               {"collisions", -kPerCollision * static_cast<double>(t.collisions) + 0.0},
               {"breaches", breaches},
               {"time", time}};
    s.formula = std::string(
                    "Pick and place: placed = 50 when the ball was grasped, released and came to "
                    "rest within 5 mm of the target, else 0. accuracy = 50 * max(0, 1 - "
                    "placement_error_m / 0.020). drops = -10 per release more than 20 mm from "
                    "the target. collisions = -5 per slave collision (each spell of the robot "
                    "inside the floor or the sheet).") +
                common;
  } else {
    const double landmarks = r.landmarks.empty()
                                 ? 100.0
                                 : 100.0 * static_cast<double>(r.landmarks_found()) /
                                       static_cast<double>(r.landmarks.size());
    s.terms = {{"landmarks", landmarks}, {"breaches", breaches}, {"time", time}};
    s.formula = std::string(
                    "Palpation: landmarks = 100 * found / landmarks (a landmark is found when the "
                    "force on it stays at or above its force_n for dwell_s without a break; 100 "
                    "when the scene names none).") +
                common;
  }
  double sum = 0.0;
  for (const auto& [name, value] : s.terms) {
    sum += value;
  }
  s.value = std::max(0.0, sum);
  return s;
}

}  // namespace hapsim
