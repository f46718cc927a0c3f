// Assessing recordings of scripted sessions, made here and replayed through the world by
// assess_recording: the knee's shipped palpation finds the landmarks its script presses and
// misses the ones it never goes near; a trajectory that presses a sphere too hard records one
// breach lasting as long as the analytic force k·depth stays above the limit.
#include "hapsim/training/recording_assessment.h"

#include "hapsim/core/error.h"
#include "hapsim/runtime/session.h"
#include "hapsim/scene/run_setup.h"
#include "hapsim/scene/scene_file.h"

#include "support/temp_dir_test.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <set>
#include <string>

namespace hapsim {
namespace {

namespace fs = std::filesystem;
const fs::path kScenes = fs::path(HAPSIM_SOURCE_DIR) / "scenes";

class RecordingAssessmentTest : public test::TempDirTest {
 protected:
  // Runs `scene_file`'s own script, recorded to `recording`; the run's summary.
  static SessionSummary record_scripted_run(const fs::path& scene_file, const fs::path& recording) {
    RunSetup setup = make_run_setup(load_scene(scene_file), DeviceChoice::scene_script());
    SessionRecorder recorder(recording, setup.world->content_hash(), 8192,
                             SessionRecorder::Overflow::kFlushInline, scene_file);
    SessionOptions options;
    options.duration_s = setup.duration_s;
    options.dt_s = setup.scene.run.dt_s;
    options.recorder = &recorder;
    options.teleop_target_world = setup.teleop_target_world;
    SessionSummary summary = run_session(*setup.world, *setup.device, options);
    recorder.close();
    return summary;
  }
};

TEST_F(RecordingAssessmentTest, TheKneesPalpationFindsTheLandmarksItPressesAndMissesTheOthers) {
  const fs::path scene_file = kScenes / "knee_paper.json";
  const fs::path recording = dir_ / "knee.rec";
  (void)record_scripted_run(scene_file, recording);
  const SceneDescription scene = load_scene(scene_file);
  ASSERT_TRUE(scene.has_assessment);
  // Written from the scene's script: it presses, in order, the LCL, the lateral joint line, the
  // tibia below the joint (the tuberosity), the medial joint line, the MCL, the patellar tendon
  // and the patella's front — seven targets; it never goes to the patella's inferior pole (the
  // apex, 26 mm below where it presses the patella), the fibula or the vastus medialis.
  const std::set<std::string> visited = {"lateral collateral ligament",
                                         "lateral joint line",
                                         "tibial tuberosity",
                                         "medial joint line",
                                         "medial collateral ligament",
                                         "patellar tendon",
                                         "patella"};
  const std::set<std::string> left_out = {"patella apex", "fibular head", "vastus medialis"};
  ASSERT_EQ(scene.device.palpation.targets.size(), visited.size());
  const RecordingAssessment a = assess_recording(recording, scene);
  EXPECT_EQ(a.replay_difference, "");
  ASSERT_EQ(a.result.landmarks.size(), visited.size() + left_out.size());
  double previous_found_s = 0.0;
  for (const LandmarkResult& l : a.result.landmarks) {
    ASSERT_TRUE(visited.count(l.name) + left_out.count(l.name) == 1) << l.name;
    EXPECT_EQ(l.found, visited.count(l.name) == 1)
        << l.name << " on " << l.segment << ": peak " << l.peak_force_n << " N, dwell " << l.dwell_s
        << " s";
    if (l.found) {
      // Found in the script's order, each during its own press (0.4 s hold after 0.4 s press).
      EXPECT_GT(l.found_at_s, previous_found_s) << l.name;
      previous_found_s = l.found_at_s;
      EXPECT_GE(l.force_at_found_n, l.required_force_n);
    }
  }
  // The palpation is gentle: no tissue over its limit.
  EXPECT_TRUE(a.result.breaches.empty());
  EXPECT_EQ(a.result.kind, "palpation");
  EXPECT_NEAR(a.result.score.value, 70.0, 1e-9);  // 7 of 10, no breach, in time
  EXPECT_NEAR(a.result.duration_s, scene.run.duration_s, 1e-9);
  EXPECT_GT(a.result.path_length_m, 0.1);
}

TEST_F(RecordingAssessmentTest, PressingTooHardRecordsOneBreachOfTheAnalyticDuration) {
  // A 5 mm probe goes straight down onto a sphere of radius 50 mm at 10 mm/s and back up:
  // depth(t) = 0.055 − z(t), z = 0.065 − 0.01·t down to t = 4 s, then back up by t = 8 s. The
  // force is k·depth = 300·depth (no damping: passivity floor 0), over the 3.0015 N limit while
  // 3·t − 3 > 3.0015: t in (2.0005, 5.9995) — 3999 cycles of 1 ms, whichever end of its cycle a
  // step samples the trajectory at.
  write("press.csv",
        "t,x,y,z,qw,qx,qy,qz\n0,0,0,0.065,1,0,0,0\n4,0,0,0.025,1,0,0,0\n8,0,0,0.065,1,0,0,0\n");
  const fs::path scene_file = write("press.json", R"({
    "format": "hapsim-scene/1",
    "world": { "passivity_damping_factor": 0 },
    "materials": { "gel": { "response": "penalty", "stiffness_n_per_m": 300,
                            "max_penetration_m": 0.05, "max_force_n": 100 } },
    "bodies": [ { "name": "ball", "geometry": { "sphere": { "radius_m": 0.05 } },
                  "materials": "gel" } ],
    "tools": [ { "name": "tip", "radius_m": 0.005 } ],
    "device": { "profile": "omega3", "trajectory": "press.csv" },
    "run": { "duration_s": 8.0 },
    "assessment": {
      "landmarks": [ { "name": "top", "segment": "ball", "point_m": [0, 0, 0.05],
                       "radius_m": 0.002, "force_n": 1.0, "dwell_s": 0.5 } ],
      "limits": [ { "segment": "ball", "max_force_n": 3.0015 } ]
    }
  })");
  const fs::path recording = dir_ / "press.rec";
  (void)record_scripted_run(scene_file, recording);
  const RecordingAssessment a = assess_recording(recording, load_scene(scene_file));
  EXPECT_EQ(a.replay_difference, "");
  ASSERT_EQ(a.result.breaches.size(), 1u);
  const BreachResult& b = a.result.breaches.front();
  EXPECT_EQ(b.tissue, "ball");
  EXPECT_NEAR(b.duration_s, 3.999, 1e-9);
  EXPECT_GE(b.start_s, 2.000 - 1e-9);
  EXPECT_LE(b.start_s, 2.001 + 1e-9);
  // The peak: 300 N/m × 30 mm at t = 4 s, within one sample's travel (10 µm, 3 mN).
  EXPECT_NEAR(b.peak_force_n, 9.0, 0.0031);
  EXPECT_NEAR(b.excess_n, 9.0 - 3.0015, 0.0031);
  EXPECT_TRUE(b.point_world.isApprox(Vec3(0, 0, 0.05), 1e-6)) << b.point_world.transpose();
  ASSERT_EQ(a.result.limits.size(), 1u);
  EXPECT_EQ(a.result.limits[0].breaches, 1u);
  // The landmark on top is found: the force passes 1 N at t = 1 + 1/3 s and stays above it for
  // far longer than the dwell.
  ASSERT_EQ(a.result.landmarks.size(), 1u);
  EXPECT_TRUE(a.result.landmarks[0].found);
  EXPECT_NEAR(a.result.landmarks[0].found_at_s, 1.0 + 1.0 / 3.0 + 0.5, 0.0021);
  // The score: 100 for the landmark, less 5 + 10 · 3.999 · (1 + 5.9985/3.0015).
  const double expected = 100.0 - (5.0 + 10.0 * 3.999 * (1.0 + (9.0 - 3.0015) / 3.0015));
  EXPECT_NEAR(a.result.score.value, std::max(0.0, expected), 0.05);
}

// The pick-and-place measures agree with what the run's own summary (the session's accountant)
// says about the same session: grasp time, peak grasp force, the ball's distance from the target,
// placed, slave collisions.
TEST_F(RecordingAssessmentTest, TheTeleopPickAndPlaceAgreesWithTheRunSummary) {
  const fs::path scene_file = kScenes / "teleop.json";
  const fs::path recording = dir_ / "teleop.rec";
  const SessionSummary summary = record_scripted_run(scene_file, recording);
  ASSERT_TRUE(summary.teleop.has_value());
  const TeleopSummary& s = *summary.teleop;

  const RecordingAssessment a = assess_recording(recording, load_scene(scene_file));
  EXPECT_EQ(a.replay_difference, "");
  EXPECT_EQ(a.result.kind, "pick_and_place");
  ASSERT_TRUE(a.result.teleop.has_value());
  const TeleopAssessment& t = *a.result.teleop;
  ASSERT_TRUE(t.time_to_grasp_s.has_value());
  EXPECT_NEAR(*t.time_to_grasp_s, s.grasp_time_s, 1e-9);
  EXPECT_NEAR(t.peak_grasp_force_n, s.peak_grasp_force_n, 1e-9);
  ASSERT_TRUE(t.placement_error_m.has_value() && s.target_error_m.has_value());
  EXPECT_NEAR(*t.placement_error_m, *s.target_error_m, 1e-9);
  EXPECT_EQ(t.placed, s.placed());
  EXPECT_TRUE(t.placed);
  EXPECT_EQ(t.drops, 0u);
  EXPECT_EQ(s.slave_collision_steps == 0, t.collisions == 0);
  // 50 placed + 50·(1 − error / 20 mm), nothing taken off.
  EXPECT_NEAR(a.result.score.value, 50.0 + 50.0 * (1.0 - *s.target_error_m / 0.020), 1e-9);
}

TEST_F(RecordingAssessmentTest, ARecordingOfAnotherSceneIsRefusedNamingIt) {
  const fs::path recording = dir_ / "other.rec";
  {
    SessionRecorder recorder(recording, "not-this-scene", 4,
                             SessionRecorder::Overflow::kFlushInline);
    RecordedFrame f;
    recorder.record(f);
    recorder.close();
  }
  try {
    (void)assess_recording(recording, load_scene(kScenes / "knee_paper.json"));
    ADD_FAILURE() << "assessed a recording of another scene";
  } catch (const Error& e) {
    EXPECT_EQ(std::string(e.where()), recording.string()) << e.what();
  }
}

}  // namespace
}  // namespace hapsim
