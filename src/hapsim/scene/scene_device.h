// The device a scene asks for: a simulated device playing the scene's trajectory file, or a
// scripted palpation aimed at named segments of the world (SPEC §10: the knee runs unattended).
#pragma once

#include "hapsim/device/palpation_trajectory.h"
#include "hapsim/device/simulated_device.h"
#include "hapsim/scene/scene_description.h"
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

/// The device of the scene: `trajectory_override` (a CSV file) if given, else the scene's
/// trajectory file, else its palpation script. Throws hapsim::Error if the scene has none.
[[nodiscard]] std::unique_ptr<SimulatedDevice> make_scene_device(
    const SceneDescription& scene, const World& world,
    const std::optional<std::filesystem::path>& trajectory_override = std::nullopt);

}  // namespace hapsim
