// A parsed scene file (docs/scene-format.md): the world it builds plus the device that drives it
// and how a run goes. Plain data; scene_file.h reads it from JSON.
#pragma once

#include "hapsim/core/types.h"
#include "hapsim/device/glove_calibration.h"
#include "hapsim/scene/assessment_definition.h"
#include "hapsim/world/world_description.h"

#include <filesystem>
#include <optional>
#include <string>
#include <vector>

namespace hapsim {

/// One press of a scripted palpation: the probe comes at the named segment from direction
/// `from_world` (a unit vector pointing from the segment towards where the probe starts), touches
/// the first surface on that line (skin, if the segment is under it) and presses `depth_m` past it.
struct PalpationTargetDescription {
  std::string body;     // body name
  std::string segment;  // segment name within the body
  /// Aim at this point (world frame) instead of the segment's centroid: a landmark inside a body
  /// that is no segment of it (the MCL inside a FEM knee's tissue). The surface met is still the
  /// body's first, coming from `from_world`.
  std::optional<Vec3> toward_world;
  Vec3 from_world = Vec3::UnitY();
  double depth_m = 0.006;
  double hold_s = 0.5;
};

struct PalpationScriptDescription {
  std::vector<PalpationTargetDescription> targets;
  double standoff_m = 0.02;
  double move_s = 1.0;
  double approach_s = 0.5;
  double press_s = 0.5;
  double release_s = 0.5;
  /// Moves between targets go round this axis (through the body's centre) on a cylinder that
  /// clears the body and the tools, instead of straight through the body. Optional.
  bool has_around_axis = false;
  Vec3 around_axis_world = Vec3::UnitZ();
  /// Longest spacing of the script's samples, seconds. Not read from the file: 1 ms matches the
  /// haptic rate; a fuzz run that steps only the first 100 cycles coarsens it (fuzz/scene_step).
  double sample_period_s = 0.001;
};

/// One finger of a glove palpation: the finger (0 thumb .. 4 little) presses the named segment,
/// or the body's surface over `toward_world` (a FEM body has no segments to name).
struct GloveFingerTarget {
  int finger = 1;
  std::string body;
  std::string segment;
  std::optional<Vec3> toward_world;
};

/// A scripted glove palpation (knee paper §3.1, the hand variant): the hand comes at the body from
/// `from_world` with its fingers formed so each chosen fingertip lands on its own segment, presses
/// `depth_m` in, holds and backs off; fingers not chosen stay curled out of the way.
struct GlovePalpationDescription {
  std::vector<GloveFingerTarget> fingers;
  Vec3 from_world = Vec3::UnitY();
  double depth_m = 0.006;
  double standoff_m = 0.03;
  double move_s = 0.8;
  double press_s = 0.6;
  double hold_s = 0.6;
  double release_s = 0.6;
  /// Longest spacing of the script's samples, seconds. Not read from the file: 1 ms matches the
  /// haptic rate; a fuzz run that steps only the first 100 cycles coarsens it (fuzz/scene_step).
  double sample_period_s = 0.001;
};

/// A scripted glove pick-and-place (the one-world scene hand_ball_sheet): the hand comes over the
/// ball with thumb and index open, goes down around it, pinches it at its equator, lifts it,
/// carries it over the sheet, presses it `press_depth_m` into the sheet, lets go and backs off.
struct GlovePickAndPlaceDescription {
  std::string ball;   ///< a dynamic body that is one sphere
  std::string sheet;  ///< a sheet body (deformation "sheet")
  /// Where on the sheet to put the ball, in the sheet's frame (x, y; metres from its centre).
  Vec3 place_sheet = Vec3::Zero();
  /// How far each fingertip presses into the ball, and how far the ball's bottom is pushed below
  /// the sheet's rest surface.
  double squeeze_m = 0.002;
  double press_depth_m = 0.01;
  /// Height of the carry above the sheet's rest surface (the ball's bottom), and how far apart
  /// beyond the ball the open fingertips pass.
  double lift_m = 0.06;
  double open_clearance_m = 0.02;
  /// Phase durations, seconds (> 0).
  double approach_s = 1.0, close_s = 0.6, lift_s = 0.8, carry_s = 1.5, lower_s = 1.0, press_s = 0.8,
         open_s = 0.5, retreat_s = 0.8, settle_s = 1.0;
  /// Longest spacing of the script's samples, seconds. Not read from the file: 1 ms matches the
  /// haptic rate; a fuzz run that steps only the first 100 cycles coarsens it (fuzz/scene_step).
  double sample_period_s = 0.001;
};

/// The teleoperation scene's scripted master (device/pick_and_place_trajectory.h): picks the ball
/// where it starts and places it at `place_m` (the ball's resting centre).
struct PickAndPlaceDescription {
  Vec3 place_m = Vec3(0.5, 0.25, 0.08);
  double clearance_m = 0.12;
  /// Seconds for the carry from above the ball to above the target.
  double carry_s = 2.0;
  /// Longest spacing of the script's samples, seconds. Not read from the file: 1 ms matches the
  /// haptic rate; a fuzz run that steps only the first 100 cycles coarsens it (fuzz/scene_step).
  double sample_period_s = 0.001;
};

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

/// A teleoperation scene (000): master arm → slave arm with a parallel gripper → ball → sheet.
struct TeleopSceneDescription {
  /// Empty: the procedural Motoman; else a URDF file and its tip link (empty: the deepest).
  std::filesystem::path slave_urdf;
  std::string slave_tip;
  double scale = 1.6;
  Vec3 offset_m = Vec3::Zero();
  double gripper_max_force_n = 20.0;
  double gripper_max_width_m = 0.10;
  double gripper_speed_m_per_s = 0.25;
  double ball_mass_kg = 0.1;
  double ball_radius_m = 0.03;
  Vec3 ball_start_m = Vec3(0.5, -0.25, 0.03);
  int sheet_nodes_per_side = 16;
  double sheet_size_m = 0.2;
  Vec3 sheet_position_m = Vec3(0.5, 0.25, 0.05);
  double floor_z_m = 0.0;
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
  /// Set for a teleoperation scene; then `world` is empty.
  bool is_teleop = false;
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
