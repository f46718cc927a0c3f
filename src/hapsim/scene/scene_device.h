// The device a scene asks for: a simulated device playing the scene's trajectory file, or a
// scripted palpation aimed at named segments of the world (architecture.md#scenes: the knee runs
// unattended).
#pragma once

#include "hapsim/device/simulated_device.h"
#include "hapsim/scene/scene_description.h"
#include "hapsim/script/palpation_trajectory.h"
#include "hapsim/world/world.h"

#include <filesystem>
#include <memory>
#include <optional>

namespace hapsim {

/// Where a palpation target lands: the first surface of `body` (any of its segments) met on the
/// line from far out along `from_world` towards the named segment's centroid, by sphere tracing
/// on the exact rest surfaces. Throws hapsim::Error naming the body/segment if nothing is hit.
struct PalpationAim {
  Vec3 surface_world = Vec3::Zero();
  std::size_t hit_segment = 0;  // segment of the body whose surface was met first
};
[[nodiscard]] PalpationAim aim_palpation_target(const World& world,
                                                const PalpationTargetDescription& target);

/// The scripted palpation of a scene, for its first tool's centre (the device point): each
/// target is pressed `depth_m` past the point where the tool sphere touches the surface.
[[nodiscard]] PalpationPlan make_scene_palpation(const World& world,
                                                 const PalpationScriptDescription& script);

/// The scripted glove palpation of a scene: the hand's orientation puts its back towards `from`
/// and its finger spread along the line between the first two targets; its position and each
/// chosen finger's angles (abduction, MCP, PIP; DIP coupled) are solved so every chosen
/// fingertip sphere presses `depth_m` into its own segment's aimed surface point, the other
/// fingers curled away. The hand comes in along −from, presses, holds and backs off. Throws
/// hapsim::Error ("glove palpation") when a finger cannot reach its target from that hand pose.
[[nodiscard]] Trajectory make_scene_glove_palpation(const World& world,
                                                    const GlovePalpationDescription& script);

/// The scripted glove pick-and-place of a scene (GlovePickAndPlaceDescription): thumb and index
/// pinch the named ball at its equator, from a hand pose (palm down) solved so both fingertips
/// reach their goals; the open pose puts them `open_clearance_m` further out on the same line.
/// Throws hapsim::Error ("glove pick-and-place") naming what is missing or out of reach.
[[nodiscard]] Trajectory make_scene_glove_pick_and_place(
    const World& world, const GlovePickAndPlaceDescription& script);

/// A trajectory file for the scene's device: a glove's raw sensor columns turned into angles by
/// the scene's calibration (scene/glove_calibration_file.h, load_glove_trajectory); raw columns
/// on any other device, or without a calibration, are an error naming the file.
[[nodiscard]] Trajectory load_device_trajectory(const SceneDescription& scene,
                                                const std::filesystem::path& file);

/// The device of the scene: `trajectory_override` (a CSV file) if given, else the scene's
/// trajectory file, else its palpation script. Throws hapsim::Error if the scene has none.
[[nodiscard]] std::unique_ptr<SimulatedDevice> make_scene_device(
    const SceneDescription& scene, const World& world,
    const std::optional<std::filesystem::path>& trajectory_override = std::nullopt);

}  // namespace hapsim
