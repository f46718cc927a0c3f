// scene_forces SCENE.json [SECONDS]: load a scene, build its world with the scene's own scripted
// device (a simulated device playing the scene's palpation), step the world at the scene's rate
// with that input, pass each command through the device's safety layer as `hapsim run` does, and
// print each tool's peak and mean force (the same figures `hapsim run --json` writes under
// "tools"). See docs/cpp.md.
#include "hapsim/core/error.h"
#include "hapsim/device/force_safety.h"
#include "hapsim/scene/run_setup.h"
#include "hapsim/scene/scene_file.h"
#include "hapsim/version.h"
#include "hapsim/world/world.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <vector>

int main(int argc, char** argv) {
  if (argc < 2) {
    std::fprintf(stderr, "usage: scene_forces SCENE.json [SECONDS]\n");
    return 2;
  }
  try {
    // The scene and its run: the world, built for the scene's device, and that device.
    hapsim::RunSetup setup =
        hapsim::make_run_setup(hapsim::load_scene(argv[1]), hapsim::DeviceChoice::scene_script());
    hapsim::World& world = *setup.world;
    hapsim::Device& device = *setup.device;
    const double dt_s = setup.scene.run.dt_s;
    const double duration_s = argc > 2 ? std::atof(argv[2]) : setup.duration_s;
    const auto steps = static_cast<std::size_t>(std::llround(duration_s / dt_s));
    std::printf("hapsim %s: %s, %s, %.3f s at %.0f Hz\n", HAPSIM_VERSION_STRING, argv[1],
                setup.device_name.c_str(), duration_s, 1.0 / dt_s);

    const auto& tools = world.description().tools;
    std::vector<double> peak(tools.size(), 0.0);
    std::vector<double> sum(tools.size(), 0.0);
    std::vector<std::size_t> touching(tools.size(), 0);
    // Between the world and the device: the command clamped to the device's rating, ramped to
    // zero if the simulation ever stalls.
    hapsim::ForceWatchdog safety(device.profile());
    for (std::size_t i = 0; i < steps; ++i) {
      const double t_s = static_cast<double>(i) * dt_s;
      const hapsim::DeviceInput input = device.read(t_s);
      const hapsim::StepResult& result = world.step(input, dt_s);
      const bool healthy =
          input.healthy && device.status().health == hapsim::DeviceHealth::kConnected;
      const hapsim::DeviceCommand out = safety.update(t_s, &result.command, healthy);
      device.write(out);

      // What the device renders for each tool: a finger's actuator force, or the tool's share
      // of the tip force.
      const double tip_n = result.command.force_world_n.norm();
      const double tip_scale = tip_n > 0.0 ? out.force_world_n.norm() / tip_n : 0.0;
      for (std::size_t t = 0; t < tools.size() && t < result.tools.size(); ++t) {
        const int finger = tools[t].finger;
        const double f = finger >= 0 && finger < out.finger_count
                             ? out.finger_force_n[static_cast<std::size_t>(finger)]
                             : result.tools[t].force_world_n.norm() * tip_scale;
        peak[t] = std::max(peak[t], f);
        if (result.tools[t].contact_count > 0) {
          sum[t] += f;
          ++touching[t];
        }
      }
    }
    for (std::size_t t = 0; t < tools.size(); ++t) {
      const double mean = touching[t] > 0 ? sum[t] / static_cast<double>(touching[t]) : 0.0;
      std::printf("tool %s: peak %.17g N, mean %.17g N, %zu steps in contact\n",
                  tools[t].name.c_str(), peak[t], mean, touching[t]);
    }
    return 0;
  } catch (const hapsim::Error& e) {
    std::fprintf(stderr, "scene_forces: %s\n", e.what());
    return 2;
  }
}
