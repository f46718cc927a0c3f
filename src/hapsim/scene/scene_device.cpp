#include "hapsim/scene/scene_device.h"

#include "hapsim/core/device_profile.h"
#include "hapsim/core/error.h"
#include "hapsim/scene/glove_calibration_file.h"
#include "hapsim/script/glove_palpation_plan.h"
#include "hapsim/script/glove_pick_and_place_plan.h"
#include "hapsim/script/scene_palpation_plan.h"
#include "hapsim/script/trajectory.h"

#include <memory>

namespace hapsim {

Trajectory load_device_trajectory(const SceneDescription& scene,
                                  const std::filesystem::path& file) {
  if (scene.device.type == "glove") {
    const DeviceDescription& d = scene.device;
    return load_glove_trajectory(file, d.glove_calibration ? &*d.glove_calibration : nullptr,
                                 d.glove_calibration_file);
  }
  Trajectory t = load_trajectory_csv(file);
  if (t.sensor_count > 0) {
    throw Error(file.string(),
                "has raw glove sensor columns s0..; only a \"glove\" device with a "
                "\"calibration\" plays them");
  }
  return t;
}

std::unique_ptr<SimulatedDevice> make_scene_device(
    const SceneDescription& scene, const World& world,
    const std::optional<std::filesystem::path>& trajectory_override) {
  const DeviceProfile& profile = device_profile(scene.device.profile);
  if (trajectory_override || !scene.device.trajectory_file.empty()) {
    const std::filesystem::path& file =
        trajectory_override ? *trajectory_override : scene.device.trajectory_file;
    return std::make_unique<SimulatedDevice>(profile, load_device_trajectory(scene, file));
  }
  if (scene.device.has_palpation) {
    return std::make_unique<SimulatedDevice>(
        profile, make_scene_palpation(world, scene.device.palpation).trajectory);
  }
  if (scene.device.has_glove_palpation) {
    return std::make_unique<SimulatedDevice>(
        profile, make_scene_glove_palpation(world, scene.device.glove_palpation));
  }
  if (scene.device.has_glove_pick_and_place) {
    return std::make_unique<SimulatedDevice>(
        profile, make_scene_glove_pick_and_place(world, scene.device.glove_pick_and_place));
  }
  throw Error(scene.file.string() + ": /device",
              "expected a 'trajectory' file or a 'palpation' script for the simulated device");
}

}  // namespace hapsim
