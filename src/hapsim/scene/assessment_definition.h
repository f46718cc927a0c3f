// What a scene says a session is judged by (docs/assessment.md): the landmarks a trainee must
// palpate (a segment, optionally a point and radius on it, with the force and dwell that count as
// "palpated"), the safe force per tissue (a segment or a material) and an optional time limit.
// Plain data: scene/assessment_reader.h reads it from a scene's "assessment"; the scorer
// (training/assessment_scorer.h) applies it to a session's cycles.
#pragma once

#include "hapsim/core/types.h"

#include <optional>
#include <string>
#include <vector>

namespace hapsim {

struct AssessmentLandmark {
  std::string name;     ///< "patella apex"
  std::string body;     ///< the body the segment is on
  std::string segment;  ///< a segment of `body`
  /// With a point: only contacts within radius_m of point_world (scene/world frame) count.
  std::optional<Vec3> point_world;
  double radius_m = 0.0;
  /// The force on the segment (newtons) held for dwell_s (continuously) that counts as palpated.
  double force_n = 1.0;
  double dwell_s = 0.2;
};

/// The safe force on a tissue: the force the tool(s) put on it above max_force_n is a breach.
struct AssessmentLimit {
  /// Either a segment (body and segment names) or a material: every segment of that material.
  std::string body;
  std::string segment;
  std::string material;
  double max_force_n = 0.0;
  /// The name results use: the segment's name, or the material's.
  [[nodiscard]] const std::string& tissue() const { return material.empty() ? segment : material; }
};

struct AssessmentDefinition {
  std::vector<AssessmentLandmark> landmarks;
  std::vector<AssessmentLimit> limits;
  /// Seconds; none when the scene sets no limit.
  std::optional<double> time_limit_s;
};

}  // namespace hapsim
