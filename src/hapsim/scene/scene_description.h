// A parsed scene file (docs/scene-format.md): the world it builds plus the device that drives it
// and how a run goes. Plain data; scene_file.h reads it from JSON. The scripts' descriptions
// (palpation targets and script, glove palpation, glove and teleop pick-and-place) are defined
// beside their planners in script/ and included here.
#pragma once

#include "hapsim/core/types.h"
#include "hapsim/device/glove_calibration.h"
#include "hapsim/scene/assessment_definition.h"
#include "hapsim/script/glove_palpation_plan.h"
#include "hapsim/script/glove_pick_and_place_plan.h"
#include "hapsim/script/palpation_aim.h"
#include "hapsim/script/scene_palpation_plan.h"
#include "hapsim/script/teleop_pick_and_place_plan.h"
#include "hapsim/world/world_description.h"

#include <filesystem>
#include <optional>
#include <string>
#include <vector>

namespace hapsim {

struct DeviceDescription {
  /// "simulated" (a stylus-like device playing a trajectory or a palpation script) or "glove"
  /// (a tracker pose plus three angles per finger, driving the virtual hand).
  std::string type = "simulated";
  /// Built-in device profile (device_profile.h), e.g. "touch", "omega3".
  std::string profile = "touch";
  /// Trajectory CSV (docs/trajectory-format.md), resolved against the scene file's folder.
  /// Empty when a palpation script drives the device.
  std::filesystem::path trajectory_file;
  bool has_palpation = false;
  PalpationScriptDescription palpation;
  bool has_pick_and_place = false;
  PickAndPlaceDescription pick_and_place;
  /// type "glove": the world's tools are the virtual hand's fingertips.
  bool has_glove_palpation = false;
  GlovePalpationDescription glove_palpation;
  /// type "glove": a scripted pick-and-place by the hand (a dynamic ball onto a sheet).
  bool has_glove_pick_and_place = false;
  GlovePickAndPlaceDescription glove_pick_and_place;
  /// type "glove": the user's calibration (docs/glove-calibration.md), read with the scene; it
  /// turns a trajectory's raw sensor columns into angles when the trajectory is loaded.
  std::filesystem::path glove_calibration_file;
  std::optional<GloveCalibration> glove_calibration;
};

/// A scene's "rig" (docs/scene-format.md#rigs, SceneDescription::has_rig): the teleoperation set-up
/// of paper 000, a master arm driving a slave arm with a parallel gripper.
struct TeleopSceneDescription {
  /// Empty: the procedural Motoman; else a URDF file and its tip link (empty: the deepest).
  std::filesystem::path slave_urdf;
  std::string slave_tip;
  /// Every slave joint's acceleration limit (SlaveFollowerOptions), rad/s² (m/s² if prismatic).
  double slave_max_acceleration_per_s2 = 30.0;
  double scale = 1.6;
  Vec3 offset_m = Vec3::Zero();
  double gripper_max_force_n = 20.0;
  double gripper_max_width_m = 0.10;
  double gripper_speed_m_per_s = 0.25;
  /// The scene's bodies the rig reads (empty: none) and the tool the slave carries (empty: none),
  /// by name; how the force at the slave's tool is scaled onto the master's hand.
  std::string ball_body;
  std::string sheet_body;
  std::string floor_body;
  std::string carried_tool;
  double force_scale = 1.0;
};

struct RunDescription {
  /// Simulated seconds; 0: until the device's trajectory or script ends.
  double duration_s = 0.0;
  /// Haptic step, seconds.
  double dt_s = 0.001;
};

/// A named camera view of the scene (docs/scene-format.md#views): `--view NAME` on snapshots.
struct SceneView {
  std::string name;
  /// Where the eye is and what it looks at, world frame, metres; vertical field of view.
  Vec3 eye_m = Vec3(0.0, -1.0, 0.5);
  Vec3 target_m = Vec3::Zero();
  double fov_deg = 40.0;
};

struct SceneDescription {
  std::filesystem::path file;  // where it was read from (empty when built in code)
  std::string description;
  /// Set for a scene with a "rig" beside its bodies and tools (also an older "teleop" file, read
  /// as one): `teleop` holds the rig, `world` the rest (the run adds the rig's bodies,
  /// scene/teleop_setup.h).
  bool has_rig = false;
  TeleopSceneDescription teleop;
  WorldDescription world;
  DeviceDescription device;
  RunDescription run;
  /// What a session is judged by ("assessment", docs/assessment.md); has_assessment when the
  /// scene declares one (`hapsim assess` refuses a scene without).
  bool has_assessment = false;
  AssessmentDefinition assessment;
  /// Named camera views ("views"), in name order.
  std::vector<SceneView> views;
  /// What the load and the run's assembly let through but a user should know, one line each,
  /// "<where>: <what>" (docs/scene-format.md, "Warnings"): a mesh implausibly sized at its scale
  /// (scene_file.h), a scripted trajectory that never comes within reach of a body
  /// (run_setup.h). Not part of the world (the content hash ignores them); `hapsim run` and
  /// `hapsim view` print each once and the run's JSON lists them.
  std::vector<std::string> warnings;
};

}  // namespace hapsim
