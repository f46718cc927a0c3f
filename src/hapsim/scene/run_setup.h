// The one place that turns a scene and a device choice into something to run: the World (built
// with the options the device needs: materials no stiffer than its rating), the device that
// drives it, how long the run lasts and what it is judged by. `hapsim run`, the viewer, the step
// benchmark and the golden tests all assemble their runs here, so they run the same thing.
#pragma once

#include "hapsim/core/device_profile.h"
#include "hapsim/device/device.h"
#include "hapsim/device/recording.h"
#include "hapsim/scene/scene_description.h"
#include "hapsim/world/world.h"

#include <filesystem>
#include <memory>
#include <optional>
#include <string>

namespace hapsim {

/// Where a run's device input comes from.
struct DeviceChoice {
  enum class Kind : std::uint8_t {
    kSceneScript,     ///< the scene's own palpation, glove palpation, pick-and-place or trajectory
    kTrajectoryFile,  ///< a trajectory CSV (docs/trajectory-format.md) instead of the scene's
    kReplay,          ///< a recording's inputs, to check the run reproduces it bit for bit
    kExternal,        ///< the caller brings the device (the viewer's mouse, a 3D mouse)
  };
  Kind kind = Kind::kSceneScript;
  std::filesystem::path file;  ///< the trajectory or the recording

  static DeviceChoice scene_script() { return {}; }
  static DeviceChoice trajectory(std::filesystem::path f) {
    return {Kind::kTrajectoryFile, std::move(f)};
  }
  static DeviceChoice replay(std::filesystem::path f) { return {Kind::kReplay, std::move(f)}; }
  static DeviceChoice external() { return {Kind::kExternal, {}}; }
};

struct RunSetupOptions {
  /// Every body's contact method, instead of the scene's.
  std::optional<ContactMethod> method;
  /// Every deformable body made static (the viewer's "deformation: none").
  bool rigid = false;
  /// A URDF slave's collision meshes: its links' bodies (they collide with the ball and are
  /// drawn). Off: a box per link between joint origins, as for a chain without meshes.
  bool load_link_meshes = true;
  /// DeviceChoice::kExternal: the device's own rated limits (a driver plugin's), instead of the
  /// scene's profile: the world renders no stiffer than this device stays stable at, and
  /// RunSetup::profile points here. Not owned; must outlive the setup. Null: the scene's.
  const DeviceProfile* external_profile = nullptr;
};

struct RunSetup {
  /// The scene as run (methods and deformation as the options chose).
  SceneDescription scene;
  /// The device's limits: the scene's profile ("simulated" for a teleoperation master).
  const DeviceProfile* profile = nullptr;
  std::unique_ptr<World> world;
  /// Null for DeviceChoice::kExternal.
  std::unique_ptr<Device> device;
  /// For summaries and window titles: "simulated omega3 (palpation script)", "replay of F", …
  std::string device_name;
  /// The scene's run.duration_s, else the device's own length (script, trajectory, recording);
  /// 0 when open-ended (an external device).
  double duration_s = 0.0;
  /// The scripted input's first sample (where an external device should start; a teleoperation
  /// master's first pose, for which the slave's start was solved).
  DeviceInput script_start;
  /// A teleoperation pick-and-place: where the ball should come to rest.
  std::optional<Vec3> teleop_target_world;
  /// A teleoperation scene's slave: "procedural Motoman" or its URDF.
  std::string slave_name;
  /// DeviceChoice::kReplay: the recording being replayed (checked frame by frame, not held: the
  /// device streams it from replayed_file).
  std::optional<RecordingScan> replayed;
  std::filesystem::path replayed_file;
};

/// Builds the run. Throws hapsim::Error naming the file and what is wrong: a recording made on
/// another scene (content hash) or with no frames, a trajectory that does not load or lacks the
/// columns the scene's device needs, a script that cannot reach its targets. A scripted device
/// (the scene's script or trajectory, or a trajectory file) whose tools never come within reach
/// of a body (trajectory_reach.h) adds a warning to the scene's warnings.
[[nodiscard]] RunSetup make_run_setup(SceneDescription scene, const DeviceChoice& choice,
                                      const RunSetupOptions& options = {});

}  // namespace hapsim
