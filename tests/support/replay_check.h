// Replays a recording the way `hapsim run --replay` does (make_run_setup with the recording as the
// device, run_session recording again) and compares the two bit for bit.
#pragma once

#include "hapsim/device/recording.h"
#include "hapsim/runtime/session.h"
#include "hapsim/scene/run_setup.h"

#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <string>

namespace hapsim::test {

/// Records a run of `setup` (its world and device, `duration_s`; its own length when 0) to `file`.
inline void record_run(RunSetup& setup, const std::filesystem::path& file,
                       double duration_s = 0.0) {
  SessionRecorder recorder(file, setup.world->content_hash(), 8192,
                           SessionRecorder::Overflow::kFlushInline);
  SessionOptions options;
  options.duration_s = duration_s > 0.0 ? duration_s : setup.duration_s;
  options.dt_s = setup.scene.run.dt_s;
  options.recorder = &recorder;
  (void)run_session(*setup.world, *setup.device, options);
  recorder.close();
}

/// True when replaying `recording` on a fresh world of `scene` reproduces every frame exactly;
/// otherwise records a test failure naming the first difference.
inline bool replays_bit_for_bit(const SceneDescription& scene,
                                const std::filesystem::path& recording) {
  RunSetup setup = make_run_setup(scene, DeviceChoice::replay(recording));
  const std::filesystem::path again =
      std::filesystem::temp_directory_path() /
      ("hapsim_replay_check_" + std::to_string(::getpid()) + ".rec");
  record_run(setup, again);
  const RecordingDifference d = compare_recording_files(setup.replayed_file, again);
  std::filesystem::remove(again);
  if (!d.identical) {
    ADD_FAILURE() << "replay of " << recording << " differs: " << d.message;
  }
  return d.identical;
}

}  // namespace hapsim::test
