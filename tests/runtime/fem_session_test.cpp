// A FEM body in a recorded session (architecture.md#deformation, "FEM bodies"): the shipped
// scenes/fem_block.json palpation, run as `hapsim run --record` runs it (FEM updates between
// cycles), replays bit for bit through the same run assembly as `hapsim run --replay`; and on the
// real-time loop the FEM thread's updates are adopted on schedule and the block is felt.
#include "hapsim/core/device_profile.h"
#include "hapsim/device/recording.h"
#include "hapsim/runtime/session.h"
#include "hapsim/scene/run_setup.h"
#include "hapsim/scene/scene_file.h"
#include "hapsim/world/fem_coupling.h"

#include <gtest/gtest.h>

#include <unistd.h>
#include <filesystem>
#include <string>

namespace hapsim {
namespace {

const std::filesystem::path kScene =
    std::filesystem::path(HAPSIM_SOURCE_DIR) / "scenes" / "fem_block.json";

std::filesystem::path temp_path(const std::string& name) {
  return std::filesystem::temp_directory_path() /
         ("hapsim_fem_session_" + std::to_string(::getpid()) + "_" + name);
}

TEST(FemSession, ARecordedPalpationOfTheFemBlockReplaysBitForBit) {
  const auto path = temp_path("a.rec");
  const auto again = temp_path("b.rec");
  constexpr double kDuration_s = 3.5;  // the end-face press and into the corner press
  {
    RunSetup run = make_run_setup(load_scene(kScene), DeviceChoice::scene_script());
    SessionRecorder recorder(path, run.world->content_hash(), 1024,
                             SessionRecorder::Overflow::kFlushInline, kScene);
    SessionOptions options;
    options.duration_s = kDuration_s;
    options.recorder = &recorder;
    const SessionSummary s = run_session(*run.world, *run.device, options);
    recorder.close();
    ASSERT_TRUE(s.fem.has_value());
    EXPECT_GT(s.tools[0].peak_force_n, 0.5) << "the script never pressed the block";
    EXPECT_EQ(s.fem->late_adopted, 0u);
    EXPECT_EQ(s.fem->updates, 350u);
  }
  RunSetup replay = make_run_setup(load_scene(kScene), DeviceChoice::replay(path));
  SessionRecorder recorder(again, replay.world->content_hash(), 1024,
                           SessionRecorder::Overflow::kFlushInline, kScene);
  SessionOptions options;
  options.duration_s = kDuration_s;
  options.recorder = &recorder;
  (void)run_session(*replay.world, *replay.device, options);
  recorder.close();
  const RecordingDifference d = compare_recordings(read_recording(path), read_recording(again));
  EXPECT_TRUE(d.identical) << d.message;
  // A stiffer block is noticed: the forces differ.
  SceneDescription stiffer = load_scene(kScene);
  auto fem = std::make_shared<FemBodyDescription>(*stiffer.world.bodies[1].fem);
  fem->materials[0].material.youngs_modulus_pa *= 2.0;
  stiffer.world.bodies[1].fem = fem;
  World other(stiffer.world);
  ReplayDevice replay2(device_profile("omega3"), read_recording(path).frames);
  const auto third = temp_path("c.rec");
  SessionRecorder recorder3(third, other.content_hash(), 1024,
                            SessionRecorder::Overflow::kFlushInline, kScene);
  options.recorder = &recorder3;
  (void)run_session(other, replay2, options);
  recorder3.close();
  EXPECT_FALSE(compare_recordings(read_recording(path), read_recording(third)).identical);
  std::filesystem::remove(path);
  std::filesystem::remove(again);
  std::filesystem::remove(third);
}

// Real time, FEM on its own thread: what a loaded CI machine can assert is progress, not speed.
TEST(FemSession, OnTheRealTimeLoopTheFemThreadKeepsTheBlockFelt) {
  RunSetup run = make_run_setup(load_scene(kScene), DeviceChoice::scene_script());
  SessionOptions options;
  options.duration_s = 2.0;  // into the end-face press
  options.realtime = true;
  const SessionSummary s = run_session(*run.world, *run.device, options);
  ASSERT_TRUE(s.fem.has_value());
  EXPECT_GT(s.fem->updates, 20u);
  EXPECT_GT(s.fem->adopted, 20u);
  EXPECT_EQ(s.fem->failures, 0u);
  EXPECT_GT(s.tools[0].peak_force_n, 0.3);
  EXPECT_EQ(s.nonfinite_commands, 0u);
}

}  // namespace
}  // namespace hapsim
