#include "hapsim/scene/run_setup.h"

#include "hapsim/core/error.h"
#include "hapsim/device/simulated_device.h"
#include "hapsim/scene/scene_device.h"
#include "hapsim/scene/teleop_setup.h"
#include "hapsim/scene/trajectory_reach.h"

#include <cstdio>
#include <string>
#include <utility>

namespace hapsim {
namespace {

// A scripted trajectory that never brings a tool within reach of a body makes a run of zeros:
// say so, naming the trajectory (its file, or the scene's script) and how far it stays.
void warn_if_out_of_reach(SceneDescription& scene, const World& world, Device& device,
                          double length_s,
                          const std::optional<std::filesystem::path>& trajectory_file) {
  const TrajectoryReach reach = trajectory_reach(world, device, length_s, scene.run.dt_s);
  if (!reach.checked || !(reach.gap_m > 0.0)) {
    return;
  }
  std::string w;
  if (trajectory_file || !scene.device.trajectory_file.empty()) {
    w = (trajectory_file ? *trajectory_file : scene.device.trajectory_file).string() +
        ": the trajectory";
  } else if (scene.device.has_glove_palpation) {
    w = scene.file.string() + ":/device/glove_palpation: the glove palpation script";
  } else {
    w = scene.file.string() + ":/device/palpation: the palpation script";
  }
  char number[64];
  std::snprintf(number, sizeof number, "%.1f mm", reach.gap_m * 1e3);
  w += std::string(" never comes within reach of a body: its tools stay at least ") + number +
       " from every body's bounding box (nearest: tool '" + reach.tool + "' to body '" +
       reach.body + "', at t = ";
  std::snprintf(number, sizeof number, "%.3f s", reach.time_s);
  w += std::string(number) + "), so nothing will be touched";
  scene.warnings.push_back(std::move(w));
}

}  // namespace

RunSetup make_run_setup(SceneDescription scene, const DeviceChoice& choice,
                        const RunSetupOptions& options) {
  for (BodyDescription& b : scene.world.bodies) {
    if (options.method) {
      b.method = *options.method;
    }
    if (options.rigid && b.kind == BodyKind::kDeformable) {
      b.kind = BodyKind::kStatic;
    }
  }
  RunSetup r;
  const std::optional<std::filesystem::path> trajectory =
      choice.kind == DeviceChoice::Kind::kTrajectoryFile
          ? std::optional<std::filesystem::path>(choice.file)
          : std::nullopt;
  std::optional<TeleopSetup> teleop;
  if (scene.has_rig) {
    // The master arm: the world is the scene's bodies and the rig's; the slave starts where the
    // master's first pose puts it (make_rig_setup solves that once).
    teleop = make_rig_setup(scene, trajectory, options.load_link_meshes);
    r.profile = &device_profile("simulated");
    r.world = std::make_unique<World>(teleop->description);
    r.slave_name = teleop->slave_name;
    if (teleop->has_target) {
      r.teleop_target_world = teleop->target_world;
    }
    r.script_start = teleop->trajectory.sample_at(teleop->trajectory.start_time_s());
  } else {
    r.profile = choice.kind == DeviceChoice::Kind::kExternal && options.external_profile != nullptr
                    ? options.external_profile
                    : &device_profile(scene.device.profile);
    WorldOptions world_options;
    // Render no stiffer than the device stays stable at (CHAI3D's published maxima).
    world_options.max_stiffness_n_per_m = r.profile->max_stiffness_n_per_m;
    r.world = std::make_unique<World>(scene.world, world_options);
  }
  for (const std::string& note : r.world->model().notes()) {
    scene.warnings.push_back(note);
  }
  double device_length_s = 0.0;
  switch (choice.kind) {
    case DeviceChoice::Kind::kReplay: {
      // Read through once, every frame checked (a corrupt file fails here, before the run), then
      // streamed by the device: memory does not grow with the recording's length.
      r.replayed = scan_recording(choice.file);
      r.replayed_file = choice.file;
      if (r.replayed->header.scene_hash != r.world->content_hash()) {
        throw Error(choice.file.string(), "recorded on a different scene (content hash differs)");
      }
      if (r.replayed->frames == 0) {
        throw Error(choice.file.string(), "the recording has no frames");
      }
      device_length_s = static_cast<double>(r.replayed->frames) * scene.run.dt_s;
      r.script_start = r.replayed->first_frame.input;
      r.device = std::make_unique<ReplayDevice>(*r.profile, choice.file, r.replayed->frames);
      r.device_name = "replay of " + choice.file.string();
      break;
    }
    case DeviceChoice::Kind::kExternal:
      if (!teleop) {
        r.script_start = DeviceInput{};
      }
      break;
    case DeviceChoice::Kind::kSceneScript:
    case DeviceChoice::Kind::kTrajectoryFile:
      if (teleop) {
        // Cycle i plays the master's trajectory at start + (i + 1)·dt: the first step moves.
        auto played = std::make_shared<const Trajectory>(std::move(teleop->trajectory));
        const double dt = scene.run.dt_s;
        device_length_s = played->end_time_s() - played->start_time_s();
        r.device = std::make_unique<SimulatedDevice>(
            *r.profile,
            [played, dt](double t_s) {
              return played->sample_at(played->start_time_s() + t_s + dt);
            },
            device_length_s);
        r.device_name = teleop->device_name;
      } else {
        auto sim = make_scene_device(scene, *r.world, trajectory);
        device_length_s = sim->duration_end_s();
        warn_if_out_of_reach(scene, *r.world, *sim, device_length_s, trajectory);
        r.script_start = sim->read(0.0);  // also the device's first read again
        // The "simulated" profile is not said twice ("simulated simulated").
        r.device_name = (r.profile->name == "simulated" ? std::string("simulated device")
                                                        : "simulated " + r.profile->name) +
                        (trajectory                   ? " playing " + trajectory->string()
                         : scene.device.has_palpation ? " (palpation script)"
                                                      : " (scene trajectory)");
        r.device = std::move(sim);
      }
      break;
  }
  // A replay runs exactly the recording's length, whatever the scene's own run length says.
  r.duration_s = choice.kind != DeviceChoice::Kind::kReplay && scene.run.duration_s > 0.0
                     ? scene.run.duration_s
                     : device_length_s;
  r.scene = std::move(scene);
  return r;
}

}  // namespace hapsim
