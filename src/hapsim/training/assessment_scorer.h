// Scores a session against its scene's assessment (docs/assessment.md), one cycle at a time:
// `hapsim assess` feeds it the cycles of a recording replayed through the world, a live viewer
// session the records it drains from the haptic loop's ring — the same code judges both. Not on
// the haptic path (it keeps the force time series: it allocates).
#pragma once

#include "hapsim/runtime/cycle_record.h"
#include "hapsim/scene/assessment_definition.h"
#include "hapsim/training/assessment_result.h"
#include "hapsim/world/world.h"

#include <cstddef>
#include <optional>
#include <vector>

namespace hapsim {

class AssessmentScorer {
 public:
  /// `world`: the world the cycles come from (segment and material names; not kept).
  /// `teleop_target_world`: a pick-and-place's target (where the ball should come to rest).
  /// Throws hapsim::Error when a landmark or limit names a segment the world lacks.
  AssessmentScorer(const AssessmentDefinition& definition, const World& world, double dt_s,
                   std::optional<Vec3> teleop_target_world = std::nullopt);

  /// The next cycle (cycles are dt_s apart; the first is at t = 0).
  void add(const CycleRecord& record);

  /// The result so far (the landmarks found, the breaches closed at this cycle) with its score.
  [[nodiscard]] AssessmentResult finish() const;

  [[nodiscard]] std::size_t cycles() const { return cycles_; }
  /// Whether landmark `i` has been found yet (the viewer colours it).
  [[nodiscard]] bool landmark_found(std::size_t i) const { return landmarks_.at(i).found; }

 private:
  struct LandmarkTrack {
    std::vector<std::size_t> flat_segments;
    std::size_t run_cycles = 0;  // current continuous cycles at or above the force
    std::size_t best_run_cycles = 0;
    std::size_t contact_cycles = 0;
    double force_sum_n = 0.0;
    double peak_force_n = 0.0;
    Vec3 peak_point_world = Vec3::Zero();
    bool found = false;
    double found_at_s = 0.0;
    double force_at_found_n = 0.0;
  };
  struct LimitTrack {
    std::vector<bool> flat_member;  // per flat segment: the tissue includes it
    bool in_breach = false;
    BreachResult open;
    std::size_t open_cycles = 0;
  };

  /// The flat index of a contact's (body, body-local segment), or flat_count_ when out of range.
  [[nodiscard]] std::size_t flat(BodyIndex body, LocalSegment segment) const;
  void close_breach(std::size_t limit_index);

  AssessmentDefinition definition_;
  double dt_s_;
  std::optional<Vec3> teleop_target_world_;
  std::vector<std::size_t> body_first_flat_;
  std::size_t flat_count_ = 0;
  std::vector<LandmarkTrack> landmarks_;
  std::vector<LimitTrack> limits_;
  std::vector<BreachResult> breaches_;
  // The force series' tissues: flat segments per column.
  std::vector<std::vector<bool>> column_members_;
  std::vector<std::string> columns_;
  std::vector<std::vector<double>> rows_;
  std::vector<double> scratch_segment_force_n_;
  std::vector<Vec3> scratch_segment_point_;
  std::vector<double> scratch_segment_best_n_;

  std::size_t cycles_ = 0;
  std::size_t contact_cycles_ = 0;
  double force_sum_n_ = 0.0;
  double peak_force_n_ = 0.0;
  double path_length_m_ = 0.0;
  std::optional<Vec3> last_path_point_;
  // Pick and place.
  bool has_teleop_ = false;
  /// The world's rig picks a ball: its cycles are scored as a pick and place (a rig that carries
  /// a probe instead, tele-palpation, is scored as a palpation by its tool's contacts).
  bool rig_picks_ball_ = false;
  std::optional<double> grasp_at_s_;
  bool held_ = false;
  bool released_ = false;
  std::size_t drops_ = 0;
  double peak_grasp_force_n_ = 0.0;
  bool colliding_ = false;
  std::size_t collisions_ = 0;
  Vec3 ball_world_ = Vec3::Zero();
  bool ball_finite_ = true;
};

/// The score of `result` (docs/assessment.md, "Score"): its value, named terms and formula text.
[[nodiscard]] AssessmentScore assessment_score(const AssessmentResult& result);

/// The 10 ms bins of forces.csv.
inline constexpr double kAssessmentForceBinS = 0.010;
/// A release farther than this from the target is a drop (docs/assessment.md).
inline constexpr double kDropDistanceM = 0.02;

}  // namespace hapsim
