// haptic_loop SCENE.json [SECONDS]: run a scene the way `hapsim run --realtime` does: the
// scene's simulated device (its scripted palpation) on the real-time haptic thread, one cycle per
// millisecond on an absolute deadline (SCHED_FIFO when permitted), the device's safety layer
// between the world and the device, FEM bodies on their own thread; then print the session's
// summary: forces per tool and how the loop kept time. See docs/cpp.md.
#include "hapsim/core/error.h"
#include "hapsim/runtime/session.h"
#include "hapsim/scene/run_setup.h"
#include "hapsim/scene/scene_file.h"

#include <cstdio>
#include <cstdlib>

int main(int argc, char** argv) {
  if (argc < 2) {
    std::fprintf(stderr, "usage: haptic_loop SCENE.json [SECONDS]\n");
    return 2;
  }
  try {
    hapsim::RunSetup setup =
        hapsim::make_run_setup(hapsim::load_scene(argv[1]), hapsim::DeviceChoice::scene_script());
    hapsim::SessionOptions options;
    options.duration_s = argc > 2 ? std::atof(argv[2]) : setup.duration_s;
    options.dt_s = setup.scene.run.dt_s;
    options.realtime = true;  // the 1 kHz haptic thread; false steps as fast as it goes
    std::printf("%s: %s, %.3f s on the real-time haptic loop\n", argv[1], setup.device_name.c_str(),
                options.duration_s);

    const hapsim::SessionSummary summary =
        hapsim::run_session(*setup.world, *setup.device, options);
    for (const hapsim::ToolSummary& tool : summary.tools) {
      std::printf("tool %s: peak %.17g N, mean %.17g N, %zu steps in contact\n", tool.name.c_str(),
                  tool.peak_force_n, tool.mean_force_n, tool.contact_steps);
    }
    std::printf("%s", hapsim::format_session_summary(summary).c_str());
    return summary.pop_throughs == 0 && summary.max_force_limit_violations == 0 ? 0 : 1;
  } catch (const hapsim::Error& e) {
    std::fprintf(stderr, "haptic_loop: %s\n", e.what());
    return 2;
  }
}
