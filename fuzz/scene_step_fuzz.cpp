// Fuzz target: bytes as a scene file, loaded, assembled into a run with the scene's own script
// (make_run_setup) and stepped for 100 cycles of 1 ms. Checks: loading and assembly return or
// throw hapsim::Error; every command the world gives is finite (NaN is the world's bug, not the
// watchdog's to hide); after the ForceWatchdog it is within the device's rating.
#include "file_fuzz_support.h"
#include "hapsim/device/force_safety.h"
#include "hapsim/scene/run_setup.h"
#include "hapsim/scene/scene_file.h"
#include "scene_fuzz_caps.h"

#include <cmath>
#include <optional>
#include <utility>

namespace {

constexpr double kScriptSamplePeriodS = 0.01;

bool finite(const hapsim::DeviceCommand& c) {
  bool ok = c.force_world_n.allFinite();
  for (double f : c.finger_force_n) {
    ok = ok && std::isfinite(f);
  }
  for (double t : c.joint_torque_nm) {
    ok = ok && std::isfinite(t);
  }
  return ok;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  hapsim::SceneLoadOptions options;
  options.data_dir = "/nonexistent/hapsim-fuzz-data";
  options.detail_caps = hapsim::fuzz::kSceneDetailCaps;
  std::optional<hapsim::RunSetup> setup;
  hapsim::fuzz::expect_value_or_error([&] {
    hapsim::SceneDescription scene = hapsim::parse_scene(
        hapsim::fuzz::as_text(data, size), "/nonexistent/hapsim-fuzz/s.json", options);
    // Only the first 100 cycles are stepped: the scripts sampled every 10 ms, not every 1 ms,
    // so building a whole palpation is not half of every input's time.
    scene.device.palpation.sample_period_s = kScriptSamplePeriodS;
    scene.device.pick_and_place.sample_period_s = kScriptSamplePeriodS;
    scene.device.glove_palpation.sample_period_s = kScriptSamplePeriodS;
    scene.device.glove_pick_and_place.sample_period_s = kScriptSamplePeriodS;
    setup.emplace(hapsim::make_run_setup(std::move(scene), hapsim::DeviceChoice::scene_script()));
  });
  if (!setup || setup->device == nullptr) {
    return 0;
  }
  hapsim::ForceWatchdog watchdog(*setup->profile);
  const double dt_s = setup->scene.run.dt_s;
  for (int i = 0; i < 100; ++i) {
    const double t_s = i * dt_s;
    const hapsim::DeviceInput input = setup->device->read(t_s);
    const hapsim::StepResult& result = setup->world->step(input, dt_s);
    HAPSIM_FUZZ_CHECK(finite(result.command), "the world's command is finite");
    const hapsim::DeviceCommand out = watchdog.update(t_s, &result.command, input.healthy);
    HAPSIM_FUZZ_CHECK(finite(out), "the watchdog's command is finite");
    HAPSIM_FUZZ_CHECK(out.force_world_n.norm() <= setup->profile->max_force_n * (1 + 1e-9),
                      "the tip force is within the device's rating");
    setup->device->write(out);
  }
  return 0;
}
