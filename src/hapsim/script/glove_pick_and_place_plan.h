// A scene's scripted glove pick-and-place planned on its world (the one-world scene
// hand_ball_sheet): thumb and index pinch the ball at its equator from a hand pose solved so both
// reach (script/hand_pose.h), lift it, carry it over the sheet, press it in, let go and back off.
// The scene file names the ball, the sheet and the timings (scene/device_reader.h).
#pragma once

#include "hapsim/core/types.h"
#include "hapsim/script/trajectory.h"

#include <string>

namespace hapsim {

class World;

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

/// The scripted glove pick-and-place of a scene (GlovePickAndPlaceDescription): thumb and index
/// pinch the named ball at its equator, from a hand pose (palm down) solved so both fingertips
/// reach their goals; the open pose puts them `open_clearance_m` further out on the same line.
/// Throws hapsim::Error ("glove pick-and-place") naming what is missing or out of reach.
[[nodiscard]] Trajectory make_scene_glove_pick_and_place(
    const World& world, const GlovePickAndPlaceDescription& script);

}  // namespace hapsim
