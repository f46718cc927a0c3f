// The device a scene asks for: a simulated device playing the scene's trajectory file, or the
// scene's scripted motion planned on its world (architecture.md#scenes: the knee runs unattended).
// The plans live in script/ (scene_palpation_plan.h, glove_palpation_plan.h,
// glove_pick_and_place_plan.h); scene/ only reads the files and chooses among them.
#pragma once

#include "hapsim/device/simulated_device.h"
#include "hapsim/scene/scene_description.h"
#include "hapsim/script/trajectory.h"
#include "hapsim/world/world.h"

#include <filesystem>
#include <memory>
#include <optional>

namespace hapsim {

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
