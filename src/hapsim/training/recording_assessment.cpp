#include "hapsim/training/recording_assessment.h"

#include "hapsim/core/error.h"
#include "hapsim/runtime/session.h"
#include "hapsim/training/assessment_scorer.h"

#include <optional>

namespace hapsim {

RecordingAssessment assess_recording(const std::filesystem::path& recording,
                                     SceneDescription scene) {
  if (!scene.has_assessment) {
    throw Error(scene.file.string(),
                "the scene has no \"assessment\" (its landmarks and limits: docs/assessment.md)");
  }
  const AssessmentDefinition definition = scene.assessment;
  RecordingAssessment out;
  out.setup = make_run_setup(std::move(scene), DeviceChoice::replay(recording));
  RunSetup& setup = out.setup;
  World& world = *setup.world;
  AssessmentScorer scorer(definition, world, setup.scene.run.dt_s, setup.teleop_target_world);
  // The replay must reproduce the recording: each cycle's frame is compared as it goes, read
  // from the file beside the replay's own stream (memory independent of the file's length).
  RecordingReader expected(setup.replayed_file, RecordingReader::TornEnd::kQuiet);
  RecordedFrame recorded;
  out.frames = setup.replayed->frames;
  SessionOptions options;
  options.duration_s = setup.duration_s;
  options.dt_s = setup.scene.run.dt_s;
  options.check_pop_through = false;
  options.teleop_target_world = setup.teleop_target_world;
  options.on_record = [&](const CycleRecord& record) {
    scorer.add(record);
    const auto i = static_cast<std::size_t>(record.cycle);
    if (out.replay_difference.empty() && i == expected.frame_index() && expected.next(recorded)) {
      const RecordedFrame again = to_recorded_frame(record, *setup.profile);
      const RecordingDifference d = compare_frames({&recorded, 1}, {&again, 1});
      if (!d.identical) {
        out.replay_difference = "frame " + std::to_string(i) + ": " + d.message;
      }
    }
  };
  (void)run_session(world, *setup.device, options);
  out.result = scorer.finish();
  return out;
}

}  // namespace hapsim
