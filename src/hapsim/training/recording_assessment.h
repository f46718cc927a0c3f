// Assesses a recorded session (docs/assessment.md): the recording's inputs replayed through its
// scene's world — bit for bit, so every contact is there (not only the 16 a frame keeps) and a
// rig's ball, grasp and collisions too — with the scorer fed every cycle. `hapsim assess` and the
// tests use it; the world is kept for a picture of the end of the session.
#pragma once

#include "hapsim/scene/run_setup.h"
#include "hapsim/scene/scene_description.h"
#include "hapsim/training/assessment_result.h"

#include <filesystem>
#include <string>

namespace hapsim {

struct RecordingAssessment {
  AssessmentResult result;
  /// The replayed run (its world as the session ended).
  RunSetup setup;
  std::size_t frames = 0;
  /// Empty when the replay reproduced every recorded frame; else where it first differed.
  std::string replay_difference;
};

/// `scene` must have an assessment (else hapsim::Error at the scene file). Throws hapsim::Error
/// naming the recording when it does not load or was made on another scene (content hash).
[[nodiscard]] RecordingAssessment assess_recording(const std::filesystem::path& recording,
                                                   SceneDescription scene);

}  // namespace hapsim
