// The assessment's outputs (docs/assessment.md; the contract with the HTML report,
// python/hapsim/assessment_report.py): the JSON (schema "hapsim.assessment/1"), the force time
// series as CSV and the short human summary every `hapsim assess` prints.
#pragma once

#include "hapsim/training/assessment_result.h"

#include <nlohmann/json.hpp>

#include <optional>
#include <string>

namespace hapsim {

/// What the JSON says about where the session came from and what was written beside it.
struct AssessmentSource {
  std::string recording;
  std::string scene;
  std::string scene_name;
  /// Beside assessment.json: the CSV's and the picture's file names (none: not written).
  std::optional<std::string> forces_file;
  std::optional<std::string> picture_file;
};

[[nodiscard]] nlohmann::json assessment_json(const AssessmentResult& result,
                                             const AssessmentSource& source);

/// forces.csv: a header line (result.force_columns), then one line per 10 ms bin (%.6g).
[[nodiscard]] std::string assessment_forces_csv(const AssessmentResult& result);

/// A few lines: landmarks found and missed, breaches, the teleop measures, the score.
[[nodiscard]] std::string format_assessment_summary(const AssessmentResult& result);

}  // namespace hapsim
