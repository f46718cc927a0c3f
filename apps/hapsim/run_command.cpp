// `hapsim run SCENE`: loads a scene, drives its world with the simulated device (the scene's
// trajectory or palpation script, another trajectory file, or a recording to replay) at 1 kHz
// simulated time, and reports contacts, forces, deflection, pop-throughs and the step cost. A
// driver plugin (`--device plugin:PATH.so`, device/plugin_device.h) is a real device instead: it
// drives the world on the real-time loop, in its own frame as the world's.
#include "commands.h"
#include "json_output.h"
#include "progress_printer.h"
#include "snapshot_view.h"
#include "stop_signal.h"

#include "hapsim/core/error.h"
#include "hapsim/core/stopwatch.h"
#include "hapsim/device/plugin_device.h"
#include "hapsim/device/recording.h"
#include "hapsim/render/force_scale.h"
#include "hapsim/render/snapshot_writer.h"
#include "hapsim/render/world_scene.h"
#include "hapsim/rig/rig_controller.h"
#include "hapsim/runtime/session.h"
#include "hapsim/runtime/session_json.h"
#include "hapsim/scene/run_setup.h"
#include "hapsim/scene/scene_file.h"

#include <spdlog/spdlog.h>
#include <nlohmann/json.hpp>

#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <functional>
#include <iostream>
#include <limits>
#include <memory>
#include <optional>
#include <sstream>
#include <string>
#include <utility>

namespace hapsim::app {
namespace {

struct RunArgs {
  std::string scene;
  std::string device;         // "sim", "sim:FILE" or "plugin:PATH.so"
  std::string driver_config;  // plugin: the string its open() gets
  double duration_s = std::numeric_limits<double>::quiet_NaN();  // NaN: not given
  std::string record_path;
  std::string replay_path;
  std::string json_path;
  std::string method;
  std::string data_dir;
  bool realtime = false;
  double spin_us = 200.0;
  bool quiet = false;
  // Headless pictures.
  std::string snapshot_path;
  std::size_t snapshot_every = 0;
  std::string display_mode = "faces";
  std::string colours = "tissue";
  std::string size = "1280x720";
  std::string view;
  std::string camera;
  std::string stereo = "off";
  bool room = false;
  double eye_separation_m = 0.0;
  int sphere_tree_level = -1;
  std::vector<std::string> overlays;
  std::vector<std::string> only_segments;
  std::vector<std::string> hide_segments;
};

// Whether a segment labelled "body/segment" is drawn under --only-segments / --hide-segments
// (each a list of parts of names).
bool segment_shown(const std::string& label, const RunArgs& args) {
  const auto named = [&label](const std::vector<std::string>& names) {
    return std::any_of(names.begin(), names.end(), [&label](const std::string& n) {
      return label.find(n) != std::string::npos;
    });
  };
  return (args.only_segments.empty() || named(args.only_segments)) && !named(args.hide_segments);
}

// Each name of --only-segments and --hide-segments must name a segment of the scene: a typo would
// otherwise show everything (or hide nothing) without a word.
void check_segment_names(const WorldDescription& d, const RunArgs& args) {
  std::vector<std::string> labels;
  for (const BodyDescription& b : d.bodies) {
    for (const SegmentDescription& seg : b.segments) {
      labels.push_back(b.name + "/" + seg.name);
    }
  }
  for (const auto* list : {&args.only_segments, &args.hide_segments}) {
    for (const std::string& name : *list) {
      if (std::none_of(labels.begin(), labels.end(), [&name](const std::string& l) {
            return l.find(name) != std::string::npos;
          })) {
        std::string all;
        for (const std::string& l : labels) {
          all += (all.empty() ? "" : ", ") + l;
        }
        throw CommandError(
            std::string(list == &args.only_segments ? "--only-segments " : "--hide-segments ") +
            name + ": no segment's name contains it (the segments: " + all + ")");
      }
    }
  }
}

SegmentColouring parse_colouring(const std::string& name) {
  if (name == "segments") {
    return SegmentColouring::kSegments;
  }
  if (name == "groups") {
    return SegmentColouring::kGroups;
  }
  if (name == "stress") {
    return SegmentColouring::kStress;
  }
  return SegmentColouring::kTissue;  // CLI11 has checked the name
}

std::pair<int, int> parse_size(const std::string& text) {
  int w = 0;
  int h = 0;
  char x = 0;
  std::istringstream in(text);
  if (!(in >> w >> x >> h) || x != 'x' || !in.eof() || w < 16 || h < 16 || w > 8192 || h > 8192) {
    throw CommandError("--size " + text + ": expected WIDTHxHEIGHT in pixels, e.g. 1280x720");
  }
  return {w, h};
}

// Headless pictures of a run, every N steps and at the end.
class SnapshotSink {
 public:
  virtual ~SnapshotSink() = default;
  /// `step` counts from 1: the picture after that many steps.
  virtual void after_step(const World& world, std::size_t step) = 0;
  virtual void final(const World& world) = 0;
};

// The same scene the viewer shows (WorldScene), drawn offscreen. The scene is built on first use
// with `make_scene`.
class RunSnapshots final : public SnapshotSink {
 public:
  using MakeScene = std::function<std::unique_ptr<WorldScene>(const World&)>;

  RunSnapshots(const RunArgs& args, MakeScene make_scene, double yaw_rad, double pitch_rad,
               std::optional<OrbitCamera> chosen)
      : args_(args),
        make_scene_(std::move(make_scene)),
        yaw_rad_(yaw_rad),
        pitch_rad_(pitch_rad),
        chosen_(std::move(chosen)) {
    const auto [w, h] = parse_size(args.size);
    writer_ = std::make_unique<SnapshotWriter>(w, h);
    writer_->set_stereo(parse_stereo_mode(args.stereo), args.eye_separation_m);
  }

  void after_step(const World& world, std::size_t step) override {
    note_contact(world);
    if (args_.snapshot_every > 0 && step % args_.snapshot_every == 0) {
      write(world, numbered_path(args_.snapshot_path, step));
    }
  }
  void final(const World& world) override {
    note_contact(world);
    if (!chosen_ && last_contact_world_) {
      // The final picture: framed on the last contact (the series keeps its first camera).
      if (!scene_) {
        scene_ = make_scene_(world);
      }
      std::vector<Vec3> tools;
      for (const ToolState& t : world.last_result().tools) {
        tools.push_back(t.p_world);
      }
      camera_ = framed_on_contact(scene_->rest_bounds_world(), *last_contact_world_, tools,
                                  static_cast<double>(writer_->width()) / writer_->height(),
                                  yaw_rad_, pitch_rad_);
      framed_ = true;
    }
    write(world, args_.snapshot_path);
    std::printf("snapshot     %s (%s, %s", args_.snapshot_path.c_str(), args_.size.c_str(),
                args_.display_mode.c_str());
    if (written_ > 1) {
      std::printf(", and %zu numbered ones", written_ - 1);
    }
    std::printf(")\n");
    if (scene_ && scene_->options().colouring == SegmentColouring::kStress) {
      // The picture's legend: FEM bodies from their own colour through yellow to red.
      std::printf("stress       FEM von Mises drawn red at %.2f kPa (yellow at half)\n",
                  scene_->fem_stress_full_scale_pa() * 1e-3);
    }
  }

 private:
  // The newest contact point of any tool, kept across steps without one.
  void note_contact(const World& world) {
    const StepResult& r = world.last_result();
    if (!r.contacts.empty()) {
      last_contact_world_ = r.contacts.front().point_world;
    }
  }

  void write(const World& world, const std::string& path) {
    if (!scene_) {
      scene_ = make_scene_(world);
    }
    if (!styled_) {
      styled_ = true;
      for (const std::string& warning : scene_->warnings()) {
        spdlog::warn("snapshot: {}", warning);
      }
      scene_->scene().style.display_mode = parse_display_mode(args_.display_mode);
    }
    if (!framed_) {
      framed_ = true;
      camera_ = chosen_ ? *chosen_
                        : framed_camera(scene_->rest_bounds_world(),
                                        static_cast<double>(writer_->width()) / writer_->height(),
                                        yaw_rad_, pitch_rad_);
    }
    scene_->update_from_world(world);
    writer_->write_png(scene_->scene(), camera_, path);
    ++written_;
  }

  const RunArgs& args_;
  MakeScene make_scene_;
  double yaw_rad_;
  double pitch_rad_;
  std::unique_ptr<SnapshotWriter> writer_;
  std::optional<OrbitCamera> chosen_;
  std::optional<Vec3> last_contact_world_;
  std::unique_ptr<WorldScene> scene_;
  bool styled_ = false;
  bool framed_ = false;
  OrbitCamera camera_;
  std::size_t written_ = 0;
};

// "5.0 N, 1000 N/m, 2 finger(s)": what a plugin's driver says its device is rated for.
std::string format_plugin_rating(const DeviceProfile& p) {
  char text[128];
  std::snprintf(text, sizeof text, "%.1f N, %.0f N/m, %d finger(s)", p.max_force_n,
                p.max_stiffness_n_per_m, p.finger_count);
  return text;
}

// What the plugin wrapper counted over the run (device/plugin_device.h): the run read the
// driver's device, and whether it refused anything the driver said.
std::string format_plugin_summary(const PluginDevice& device) {
  const PluginDeviceCounts n = device.counts();
  const DeviceStatus status = device.status();
  char text[400];
  std::snprintf(text, sizeof text,
                "plugin       '%s': %llu reads (%llu without a new sample, %llu refused as "
                "non-finite or out of range), %llu commands sent as zero, %llu refused by the "
                "driver; health at the end: %s\n",
                device.driver_name().c_str(), static_cast<unsigned long long>(n.reads),
                static_cast<unsigned long long>(n.no_sample),
                static_cast<unsigned long long>(n.bad_samples),
                static_cast<unsigned long long>(n.commands_zeroed),
                static_cast<unsigned long long>(n.write_refused),
                std::string(to_string(status.health)).c_str());
  return text;
}

nlohmann::json plugin_summary_json(const PluginDevice& device) {
  const PluginDeviceCounts n = device.counts();
  const DeviceProfile& p = device.profile();
  return {{"driver", device.driver_name()},
          {"model", p.display_name},
          {"path", device.path().string()},
          {"max_force_n", p.max_force_n},
          {"max_stiffness_n_per_m", p.max_stiffness_n_per_m},
          {"fingers", p.finger_count},
          {"reads", n.reads},
          {"no_sample", n.no_sample},
          {"bad_samples", n.bad_samples},
          {"commands_zeroed", n.commands_zeroed},
          {"write_refused", n.write_refused},
          {"health", std::string(to_string(device.status().health))}};
}

ContactMethod parse_method(const std::string& name) {
  return parse_contact_method(name).value_or(ContactMethod::kKnee);  // CLI11 has checked it
}

void run(const RunArgs& args) {
  ProgressPrinter printer;
  const ProgressFn progress = [&printer, &args](std::string_view label, double fraction) {
    if (!args.quiet) {
      printer(label, fraction);
    }
  };
  // Open outputs first, so a bad path fails before the run.
  JsonOutput json_out(args.json_path);
  // Options that cannot work are refused before anything is loaded or printed.
  if (!std::isnan(args.duration_s) &&
      (!(args.duration_s > 0.0) || !std::isfinite(args.duration_s))) {
    throw CommandError("--duration: expected seconds > 0");
  }
  // A driver plugin is a real device: its hand moves in wall-clock time, so the world steps on
  // the real-time loop.
  const std::optional<std::filesystem::path> plugin = plugin_path_from_device_spec(args.device);
  const bool realtime = args.realtime || plugin.has_value();
  if (!plugin && !args.driver_config.empty()) {
    throw CommandError("--driver-config: only with --device plugin:PATH.so");
  }
  if (plugin && !args.replay_path.empty()) {
    throw CommandError("--device and --replay both choose the input: give one");
  }
  if (realtime && args.snapshot_every > 0) {
    throw CommandError(std::string("--snapshot-every: not with ") +
                       (args.realtime ? "--realtime" : "a plugin device (it runs in real time)") +
                       " (the haptic thread owns the world while it runs; the final snapshot is "
                       "written after the run)");
  }
  if (!args.snapshot_path.empty()) {
    // Fail before the run, not after it: the folder must be there.
    const std::filesystem::path folder = std::filesystem::path(args.snapshot_path).parent_path();
    if (!folder.empty() && !std::filesystem::is_directory(folder)) {
      throw CommandError("--snapshot " + args.snapshot_path + ": no such folder " +
                         folder.string());
    }
    (void)parse_size(args.size);
    (void)chosen_snapshot_camera({}, "", args.camera);  // a bad --camera fails before loading
    try {
      (void)parse_stereo_mode(args.stereo);
    } catch (const Error& e) {
      throw CommandError(e.what());
    }
    if (!(args.eye_separation_m >= 0.0) || !std::isfinite(args.eye_separation_m)) {
      throw CommandError("--eye-separation: expected metres >= 0 (0: a thirtieth of the distance)");
    }
  } else if (!args.view.empty() || !args.camera.empty() || !args.overlays.empty() ||
             !args.only_segments.empty() || !args.hide_segments.empty()) {
    throw CommandError(std::string(!args.view.empty()            ? "--view"
                                   : !args.camera.empty()        ? "--camera"
                                   : !args.overlays.empty()      ? "--overlay"
                                   : !args.only_segments.empty() ? "--only-segments"
                                                                 : "--hide-segments") +
                       ": only with --snapshot FILE.png");
  }
  std::optional<std::filesystem::path> trajectory;
  if (!args.device.empty() && args.device != "sim" && !plugin) {
    if (args.device.rfind("sim:", 0) != 0 || args.device.size() <= 4) {
      throw CommandError("--device " + args.device +
                         ": expected 'sim', 'sim:FILE' (a trajectory CSV for the simulated "
                         "device) or 'plugin:PATH.so' (a driver, include/hapsim/device_driver.h)");
    }
    trajectory = args.device.substr(4);
  }
  if (trajectory && !args.replay_path.empty()) {
    throw CommandError("--device and --replay both choose the input: give one");
  }

  // The driver is opened before the scene loads: a wrong one is one line at once.
  std::unique_ptr<PluginDevice> plugin_device;
  if (plugin) {
    plugin_device = open_plugin_device(*plugin, args.driver_config);
  }

  SceneLoadOptions load_options;
  if (!args.data_dir.empty()) {
    load_options.data_dir = args.data_dir;
  }
  load_options.progress = progress;
  load_options.device_trajectory_played = !trajectory && args.replay_path.empty() && !plugin;
  const Stopwatch load_watch;
  SceneDescription loaded = load_scene(args.scene, load_options);
  if (!args.method.empty() && loaded.world.bodies.empty()) {
    throw CommandError("--method: " + args.scene +
                       " has no bodies whose contact method it could change");
  }
  const DeviceChoice choice = plugin                      ? DeviceChoice::external()
                              : !args.replay_path.empty() ? DeviceChoice::replay(args.replay_path)
                              : trajectory                ? DeviceChoice::trajectory(*trajectory)
                                                          : DeviceChoice::scene_script();
  RunSetupOptions setup_options;
  if (plugin_device) {
    // The world renders no stiffer than the plugin's device is rated for.
    setup_options.external_profile = &plugin_device->profile();
  }
  if (!args.method.empty()) {
    setup_options.method = parse_method(args.method);
  }
  report_progress(progress, "building the world", 0.0);
  RunSetup setup = [&] {
    try {
      return make_run_setup(std::move(loaded), choice, setup_options);
    } catch (const Error& e) {
      // A bad recording is a bad --replay argument: say so.
      if (choice.kind == DeviceChoice::Kind::kReplay &&
          std::string(e.where()) == args.replay_path) {
        throw CommandError("--replay " + args.replay_path + ": " + e.what());
      }
      throw;
    }
  }();
  const SceneDescription& scene = setup.scene;
  check_segment_names(scene.world, args);
  PluginDevice* driven_by_plugin = plugin_device.get();
  if (plugin_device) {
    if (rig_state(*setup.world) != nullptr) {
      throw CommandError("--device " + args.device + ": " + args.scene +
                         " is a teleoperation scene, whose master arm its script drives; a "
                         "plugin drives probe and glove scenes");
    }
    setup.device_name = "plugin '" + plugin_device->driver_name() + "' (" + plugin->string() +
                        ", rated " + format_plugin_rating(plugin_device->profile()) + ")";
    setup.device = std::move(plugin_device);
  }
  const std::optional<OrbitCamera> chosen_camera =
      args.snapshot_path.empty() ? std::nullopt
                                 : chosen_snapshot_camera(scene, args.view, args.camera);
  std::unique_ptr<World>& world = setup.world;
  std::unique_ptr<Device>& device = setup.device;
  const std::string& device_name = setup.device_name;
  const std::optional<RecordingScan>& replayed = setup.replayed;
  const bool teleop = rig_state(*world) != nullptr;
  if (teleop) {
    const RigState& rig = *rig_state(*world);
    if (rig.description->ball_body == TeleopRigDescription::kNoBody) {
      const std::size_t tool = rig.description->carried_tool;
      std::printf(
          "scene        %s: teleoperation, slave %s (%d joints) carrying tool '%s', %zu "
          "bodies of the scene\n",
          scene.file.string().c_str(), setup.slave_name.c_str(), rig.slave->chain().dof(),
          tool < scene.world.tools.size() ? scene.world.tools[tool].name.c_str() : "none",
          scene.world.bodies.size());
    } else {
      std::printf(
          "scene        %s: teleoperation, slave %s (%d joints), ball %.0f g r %.0f mm, "
          "sheet %dx%d\n",
          scene.file.string().c_str(), setup.slave_name.c_str(), rig.slave->chain().dof(),
          rig.description->ball.mass_kg * 1e3, rig.description->ball.radius_m * 1e3,
          rig.description->sheet.nodes_per_side, rig.description->sheet.nodes_per_side);
    }
  } else {
    std::size_t vertices = 0;
    std::size_t segments = 0;
    for (const BodyDescription& b : scene.world.bodies) {
      for (const SegmentDescription& seg : b.segments) {
        vertices += seg.mesh.vertex_count();
        ++segments;
      }
    }
    std::printf(
        "scene        %s: %zu bodies, %zu segments, %zu vertices, %zu tool(s); loaded and "
        "built in %.2f s (world %.0f ms, %.1f MB of query structures)\n",
        args.scene.c_str(), scene.world.bodies.size(), segments, vertices, scene.world.tools.size(),
        load_watch.elapsed_s(), world->build_ms(),
        static_cast<double>(world->query_memory_bytes()) / 1e6);
  }
  double duration_s = setup.duration_s;
  if (!std::isnan(args.duration_s)) {
    duration_s = args.duration_s;  // checked above
  }
  if (!(duration_s > 0.0) || !std::isfinite(duration_s)) {
    throw CommandError(args.scene + ": the run has no length (give --duration S)");
  }
  if (const double steps = duration_s / scene.run.dt_s; !(steps <= max_session_steps(realtime))) {
    char text[200];
    std::snprintf(text, sizeof text,
                  ": a run of %g s at run.dt_s %g s is %.3g steps; at most %.0e %s (give a "
                  "shorter --duration)",
                  duration_s, scene.run.dt_s, steps, max_session_steps(realtime),
                  realtime ? "in real time" : "as fast as possible");
    throw CommandError(args.scene + text);
  }
  std::printf("device       %s; %.3f s at %.0f Hz%s\n", device_name.c_str(), duration_s,
              1.0 / scene.run.dt_s,
              !realtime       ? " as fast as possible"
              : args.realtime ? " in real time"
                              : " in real time (a plugin's device runs on the real-time loop)");
  // What the load and the run's assembly let through but noticed: through the log, as mesh
  // defects are, once each, before the run (and in the JSON).
  for (const std::string& warning : scene.warnings) {
    spdlog::warn("{}", warning);
  }

  // A replay without --record still records, to a temporary file, to compare bit for bit.
  std::filesystem::path record_path = args.record_path;
  bool temporary_record = false;
  if (record_path.empty() && replayed) {
    record_path = std::filesystem::temp_directory_path() /
                  ("hapsim_replay_" + std::to_string(::getpid()) + ".rec");
    temporary_record = true;
  }
  // SIGINT and SIGTERM from here on stop the run as its end would: the loop stops (the device
  // gets a zero command), then the summary, the JSON and the recording's end are written, and
  // the exit status is 128 + the signal. (Before this a signal ends the program at once: nothing
  // has been written yet.)
  const std::atomic<bool>& stop = install_stop_signals();
  // The recorder is flushed every 100 ms of the run, off the haptic thread (session.cpp): a
  // killed run keeps all but its last 100 ms.
  std::unique_ptr<SessionRecorder> recorder;
  if (!record_path.empty()) {
    recorder = make_session_recorder(record_path, *world, args.scene);
  }

  std::unique_ptr<SnapshotSink> snapshots;
  if (!args.snapshot_path.empty()) {
    snapshots = std::make_unique<RunSnapshots>(
        args,
        [&args, &setup](const World& w) {
          WorldSceneOptions o;
          o.force_full_scale_n = force_display_scale_n(
              w.description(), rig_state(w) != nullptr
                                   ? rig_description(w.description())->gripper.max_force_n
                                   : device_rated_force_n(*setup.profile));
          o.colouring = parse_colouring(args.colours);
          o.show_room = args.room;
          o.sphere_tree_level = args.sphere_tree_level;
          for (const std::string& overlay : args.overlays) {
            o.show_influence_spheres |= overlay == "influence";
            o.show_contact_vertices |= overlay == "contact-vertices";
          }
          auto drawn = std::make_unique<WorldScene>(w, o);
          // Only ever hidden here: what the scene itself does not draw (a rig's floor slab, links
          // drawn by the slave's figure) stays hidden.
          for (std::size_t i = 0; i < drawn->segment_count(); ++i) {
            if (!segment_shown(drawn->segment_label(i), args)) {
              drawn->set_segment_visible(i, false);
            }
          }
          drawn->set_options(o);  // the overlays again, for the segments now shown
          return drawn;
        },
        snapshot_yaw_rad(*world), snapshot_pitch_rad(*world), chosen_camera);
  }

  SessionOptions options;
  options.duration_s = duration_s;
  if (snapshots && !realtime) {
    // Every step: numbered pictures, and the last contact the final picture is framed on.
    options.after_cycle = [&](std::size_t cycle) { snapshots->after_step(*world, cycle + 1); };
  }
  options.dt_s = scene.run.dt_s;
  options.realtime = realtime;
  options.loop.spin_s = 1e-6 * args.spin_us;
  options.recorder = recorder.get();
  options.progress = progress;
  options.teleop_target_world = setup.teleop_target_world;
  options.stop = &stop;
  SessionSummary summary = run_session(*world, *device, options);
  const int stopped_by = stop.load() ? stop_signal_number().load() : 0;
  if (recorder) {
    finish_session_recording(*recorder, summary);
  }
  std::cout << format_session_summary(summary);
  if (driven_by_plugin != nullptr) {
    std::cout << format_plugin_summary(*driven_by_plugin);
  }
  if (summary.realtime) {
    // What `hapsim doctor` explains, with the fix (docs/doctor.md).
    if (!summary.realtime->realtime_priority) {
      std::printf(
          "warning      the haptic thread ran without SCHED_FIFO (normal scheduling: millisecond "
          "jitter); run `hapsim doctor` for the fix\n");
    }
    if (!summary.realtime->memory_locked) {
      std::printf(
          "warning      the haptic loop ran with its memory unlocked (a page read back from "
          "swap can stall a cycle); run `hapsim doctor` for the fix\n");
    }
  }
  if (stopped_by != 0) {
    std::printf(
        "interrupted  by %s after %.3f of %.3f s: the summary and what is written below cover "
        "the run so far\n",
        stop_signal_name(), summary.simulated_s, duration_s);
  }
  if (snapshots) {
    snapshots->final(*world);
  }

  std::optional<RecordingDifference> replay_difference;
  if (replayed) {
    // Frame by frame from both files: memory does not grow with the recording.
    replay_difference = compare_recording_files(setup.replayed_file, record_path);
    if (replay_difference->identical) {
      std::printf("replay       identical to %s, bit for bit (%zu frames)\n",
                  args.replay_path.c_str(), replayed->frames);
    } else {
      std::printf("replay       DIFFERS from %s: %s\n", args.replay_path.c_str(),
                  replay_difference->message.c_str());
    }
    if (temporary_record) {
      std::error_code ec;
      std::filesystem::remove(record_path, ec);
    }
  } else if (recorder) {
    std::printf("recorded     %s (%zu frames)\n", record_path.string().c_str(),
                recorder->frames_written());
  }
  for (const std::string& failure : run_failures(setup, summary)) {
    std::printf("FAILED: %s\n", failure.c_str());
  }
  nlohmann::json j =
      run_summary_json(setup, summary, replay_difference ? &*replay_difference : nullptr);
  const bool failed = !j["ok"].get<bool>();
  if (driven_by_plugin != nullptr) {
    j["plugin"] = plugin_summary_json(*driven_by_plugin);
  }
  if (stopped_by != 0) {                   // "interrupted": true says it too (run_summary_json)
    j["stopped_by"] = stop_signal_name();  // as watch, serve and device say it
  }
  if (json_out) {
    json_out.write(j);
  }
  if (failed) {
    exit_status() = summary.recording_error.empty() ? 1 : 2;  // 2: an output was not written
  }
  if (stopped_by != 0) {
    exit_status() = stopped_by_signal_status();  // 128 + the signal, as a shell reports it
  }
}

}  // namespace

void add_run_command(CLI::App& app) {
  auto args = std::make_shared<RunArgs>();
  CLI::App* cmd = app.add_subcommand(
      "run", "Run a scene: the haptic step at 1 kHz driven by the simulated device");
  cmd->add_option("scene", args->scene, "Scene file (JSON, see docs/scene-format.md)")->required();
  cmd->add_option("--device", args->device,
                  "sim (the scene's own trajectory or palpation script), sim:FILE (play a "
                  "trajectory CSV) or plugin:PATH.so (a driver, include/hapsim/device_driver.h: "
                  "its device drives the world in real time, its frame the world's; give "
                  "--duration)");
  cmd->add_option("--driver-config", args->driver_config,
                  "plugin: the string its open() gets (e.g. a serial port)");
  cmd->add_option("--duration", args->duration_s,
                  "Simulated seconds (default: the scene's run.duration_s, else until the "
                  "trajectory ends)")
      ->check(positive_seconds());
  cmd->add_option("--record", args->record_path, "Record every cycle to FILE (binary)");
  cmd->add_option("--replay", args->replay_path,
                  "Drive the world with a recording's inputs and check the run reproduces it "
                  "bit for bit");
  cmd->add_option("--json", args->json_path, "Write the summary as JSON to FILE");
  cmd->add_option("--method", args->method, "Override every body's contact method")
      ->check(CLI::IsMember({"exact", "spheretree", "knee"}));
  cmd->add_option("--data", args->data_dir,
                  "Real-data folder for scenes that use one (e.g. ../shared/data/knee_vhf_left)");
  cmd->add_flag("--realtime", args->realtime,
                "Run on the real-time haptic thread: an absolute 1 kHz deadline (SCHED_FIFO when "
                "permitted), stall watchdog; the summary adds rate, period jitter and missed "
                "deadlines");
  cmd->add_option("--spin-us", args->spin_us,
                  "Real time with SCHED_FIFO: wake this long before each deadline and spin to it "
                  "(default 200, at most 500; 0 sleeps only)")
      ->check(CLI::Range(0.0, 500.0));
  cmd->add_flag("-q,--quiet", args->quiet, "No progress lines");
  cmd->add_option("--snapshot", args->snapshot_path,
                  "Write a picture of the final state to FILE.png (offscreen: no display needed)");
  cmd->add_option("--snapshot-every", args->snapshot_every,
                  "Also write FILE_NNNNNN.png every N cycles (not with --realtime)")
      ->check(CLI::PositiveNumber);
  cmd->add_option("--display-mode", args->display_mode, "Snapshot display mode")
      ->check(CLI::IsMember({"points", "lines", "faces"}));
  cmd->add_option("--colours", args->colours,
                  "Snapshot colouring: tissue (by material), segments, groups (knee method's "
                  "vertex groups) or stress (FEM bodies by von Mises stress)")
      ->check(CLI::IsMember({"tissue", "segments", "groups", "stress"}));
  cmd->add_option("--size", args->size, "Snapshot size WIDTHxHEIGHT (default 1280x720)");
  cmd->add_option("--view", args->view,
                  "Snapshot from the scene's named view NAME (its \"views\"; default: the final "
                  "picture framed on the last contact)");
  cmd->add_flag("--room", args->room,
                "Snapshot with the room's walls on the floor's far edges (the knee paper's world)");
  cmd->add_option("--stereo", args->stereo,
                  "Snapshot in stereo: off (default), side-by-side (left eye left) or anaglyph "
                  "(red-cyan)");
  cmd->add_option("--eye-separation", args->eye_separation_m,
                  "Stereo eye separation, metres (default: a thirtieth of the view distance)");
  cmd->add_option("--camera", args->camera,
                  "Snapshot from EX,EY,EZ,TX,TY,TZ,FOV: eye and target (world, m) and vertical "
                  "field of view (degrees)");
  cmd->add_option("--sphere-tree-level", args->sphere_tree_level,
                  "Draw the sphere tree's spheres at this level in the snapshot (root = 0)")
      ->check(CLI::NonNegativeNumber);
  cmd->add_option(
         "--overlay", args->overlays,
         "Snapshot overlays of the knee method (the knee paper's Fig. 3), comma-separated: "
         "influence (each vertex group's sphere of influence), contact-vertices (the "
         "three vertices closest in angle to a touching tool within 1 cm of a shown segment)")
      ->delimiter(',')
      ->check(CLI::IsMember({"influence", "contact-vertices"}));
  cmd->add_option("--only-segments", args->only_segments,
                  "Snapshot only the segments whose body/segment name contains one of these "
                  "(comma-separated); the world still has them all")
      ->delimiter(',');
  cmd->add_option("--hide-segments", args->hide_segments,
                  "Snapshot without the segments whose body/segment name contains one of these "
                  "(comma-separated), e.g. Skin")
      ->delimiter(',');
  cmd->callback([args] { run(*args); });
}

}  // namespace hapsim::app
