// `hapsim view SCENE`: the interactive viewer (src/hapsim/ui/viewer.h) — palpate with the mouse,
// watch forces and deformation. Needs a display (or xvfb-run); headless machines use
// `hapsim run SCENE --snapshot FILE.png`.
#include "commands.h"
#include "dds_options.h"
#include "stop_signal.h"

#include "hapsim/core/error.h"
#include "hapsim/device/plugin_device.h"
#include "hapsim/render/snapshot_writer.h"
#include "hapsim/ui/viewer.h"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <memory>
#include <sstream>
#include <string>
#include <vector>

namespace hapsim::app {
namespace {

struct ViewArgs {
  std::string scene;
  std::string data_dir;
  std::string device = "mouse";
  std::string driver_config;  // plugin: the string its open() gets
  std::string method;
  std::string deformation = "deflection";
  std::string size = "1280x720";
  bool no_vsync = false;
  bool no_panels = false;
  double panels_hz = 20.0;
  int msaa = 0;
  std::string stereo = "off";
  double eye_separation_m = 0.0;
  double duration_s = 0.0;
  std::string view;
  std::string camera;
  bool room = false;
  std::vector<std::string> overlays;
  std::string screenshot;
  std::string first_screenshot;
  std::string json;
  bool quiet = false;
  bool connect = false;
  DdsOptions dds;
};

// The viewer's own errors for a machine without a display or a usable OpenGL window (ui/viewer.cpp
// throws them as Error("viewer", …)) get the pointer to `hapsim doctor`, which says what is
// missing and how to fix it.
int run_viewer_or_say_doctor(const ViewerOptions& o) {
  try {
    return run_viewer(o);
  } catch (const Error& e) {
    if (e.where() == "viewer") {
      throw CommandError(std::string(e.what()) + "; run `hapsim doctor` for the fix");
    }
    throw;
  }
}

void view(const ViewArgs& args) {
  const bool plugin = plugin_path_from_device_spec(args.device).has_value();
  if (!plugin && !args.driver_config.empty()) {
    throw CommandError("--driver-config: only with --device plugin:PATH.so");
  }
  if (plugin && args.connect) {
    throw CommandError("--device " + args.device +
                       ": --connect draws a served world, whose devices its hosts drive "
                       "(hapsim device --device plugin:PATH.so)");
  }
  if (plugin) {
    // The viewer's session opens the driver itself (ui/world_viewer_session.cpp; again for each
    // scene chosen in the menu); a driver that does not load or open is one line here, before
    // any window.
    (void)open_plugin_device(*plugin_path_from_device_spec(args.device), args.driver_config);
  }
  if (args.connect == !args.scene.empty()) {
    throw CommandError(args.connect ? "--connect takes its scene from the simulation host: give "
                                      "no scene file"
                                    : "give a scene file, or --connect to a simulation host");
  }
  ViewerOptions o;
  o.config.connect = args.connect;
  o.config.session = args.dds.session;
  o.config.domain = args.dds.domain;
  o.config.interface = args.dds.interface;
  o.config.peers = args.dds.peers;
  if (args.connect && args.dds.secure()) {
    const net::DdsNetwork network = args.dds.network();  // checked here: one line, exit 2
    o.config.security = network.security;
    o.config.security_label = network.security_label;
  }
  o.config.scene = args.scene;
  o.config.data_dir = args.data_dir;
  o.config.device = args.device;
  o.config.driver_config = args.driver_config;
  o.config.method = args.method;
  o.config.deformation = args.deformation;
  char x = 0;
  std::istringstream size(args.size);
  if (!(size >> o.width_px >> x >> o.height_px) || x != 'x' || !size.eof() || o.width_px < 320 ||
      o.height_px < 240 || o.width_px > 8192 || o.height_px > 8192) {
    throw CommandError("--size " + args.size +
                       ": expected WIDTHxHEIGHT, from 320x240 to 8192x8192 pixels");
  }
  o.vsync = !args.no_vsync;
  o.panels = !args.no_panels;
  o.panel_refresh_hz = args.panels_hz;
  o.msaa_samples = args.msaa;
  try {
    o.stereo = parse_stereo_mode(args.stereo);
  } catch (const Error& e) {
    throw CommandError(e.what());
  }
  if (!(args.eye_separation_m >= 0.0) || !std::isfinite(args.eye_separation_m)) {
    throw CommandError("--eye-separation: expected metres >= 0 (0: a thirtieth of the distance)");
  }
  o.eye_separation_m = args.eye_separation_m;
  if (!std::isfinite(args.duration_s)) {
    throw CommandError("--duration: expected seconds >= 0 (0: until the window is closed)");
  }
  o.duration_s = args.duration_s;
  if (args.connect && (!args.view.empty() || args.room)) {
    throw CommandError(std::string(!args.view.empty() ? "--view" : "--room") +
                       ": a scene file's option; --connect takes the scene from the host "
                       "(--camera works)");
  }
  if (!args.view.empty() && !args.camera.empty()) {
    throw CommandError("--view and --camera: give one of them");
  }
  if (!args.camera.empty()) {
    try {
      (void)parse_camera_spec(args.camera);  // a bad spec fails before the window opens
    } catch (const Error& e) {
      throw CommandError(e.what());
    }
  }
  o.view = args.view;
  o.camera = args.camera;
  o.room = args.room;
  for (const std::string& overlay : args.overlays) {
    (overlay == "influence" ? o.influence_overlay : o.contact_vertices_overlay) = true;
  }
  o.screenshot = args.screenshot;
  o.first_screenshot = args.first_screenshot;
  o.json = args.json;
  o.quiet = args.quiet;
  o.stop = &install_stop_signals();  // SIGINT/SIGTERM close the window as the user would
  // The scene menu offers the scene files beside the one opened.
  if (args.connect) {
    exit_status() = with_signal_status(run_viewer_or_say_doctor(o));
    return;
  }
  const std::filesystem::path folder = std::filesystem::path(args.scene).parent_path();
  std::error_code ec;
  for (const auto& entry : std::filesystem::directory_iterator(
           folder.empty() ? std::filesystem::path(".") : folder, ec)) {
    if (entry.path().extension() == ".json" &&
        entry.path().filename().string().find("schema") == std::string::npos) {
      o.scene_choices.push_back(entry.path());
    }
  }
  std::sort(o.scene_choices.begin(), o.scene_choices.end());
  exit_status() = with_signal_status(run_viewer_or_say_doctor(o));
}

}  // namespace

void add_view_command(CLI::App& app) {
  auto args = std::make_shared<ViewArgs>();
  CLI::App* cmd = app.add_subcommand(
      "view",
      "Open the 3D viewer: palpate a scene with the mouse on the real-time haptic loop, or "
      "--connect to a served one");
  cmd->add_option("scene", args->scene, "Scene file (JSON); none with --connect")
      ->check(CLI::ExistingFile);
  cmd->add_flag("--connect", args->connect,
                "Draw the world a simulation host serves (hapsim serve) instead of running one");
  add_dds_options(cmd, args->dds, net::SecurityRole::kViewer);
  cmd->add_option("--data", args->data_dir, "Real-data folder for scenes that use one");
  cmd->add_option("--device", args->device,
                  "mouse (the viewer's probe), sim (the scene's script), sim:FILE (a trajectory "
                  "CSV), spacemouse (a 3D mouse via spacenavd) or plugin:PATH.so (a device "
                  "driver, include/hapsim/device_driver.h)");
  cmd->add_option("--driver-config", args->driver_config,
                  "With --device plugin:PATH.so: the string the driver's open() gets");
  cmd->add_option("--method", args->method, "Override every body's contact method")
      ->check(CLI::IsMember({"exact", "spheretree", "knee"}));
  cmd->add_option("--deformation", args->deformation,
                  "deflection (vertex deflection, eq. 1) or none (every body rigid)")
      ->check(CLI::IsMember({"deflection", "none"}));
  cmd->add_option("--size", args->size, "Window size WIDTHxHEIGHT (default 1280x720)");
  cmd->add_flag("--no-vsync", args->no_vsync, "Draw as fast as possible (to measure fps)");
  cmd->add_flag("--no-panels", args->no_panels,
                "Start with the control and data areas hidden (Tab shows them)");
  cmd->add_option("--panels-hz", args->panels_hz,
                  "On a software rasteriser, redraw the panels at least N times a second while "
                  "nothing happens on them and draw the 3D view alone in between (default 20; "
                  "0: the panels every frame)")
      ->check(CLI::Range(0.0, 1000.0));
  cmd->add_option("--stereo", args->stereo,
                  "Stereo view: off (default), side-by-side (left eye left) or anaglyph "
                  "(red-cyan); V cycles them");
  cmd->add_option("--eye-separation", args->eye_separation_m,
                  "Stereo eye separation, metres (default: a thirtieth of the view distance)");
  cmd->add_option("--msaa", args->msaa,
                  "Multisample anti-aliasing samples (default 0: costly on a software rasteriser)")
      ->check(CLI::Range(0, 16));
  cmd->add_option("--duration", args->duration_s, "Close after S seconds (default: when closed)")
      ->check(CLI::NonNegativeNumber);
  cmd->add_option("--view", args->view,
                  "Look first from the scene's named view NAME (its \"views\")");
  cmd->add_option("--camera", args->camera,
                  "Look first from EYE to TARGET: ex,ey,ez,tx,ty,tz,fov (metres, world frame; "
                  "field of view in degrees)");
  cmd->add_flag("--room", args->room,
                "Show the knee paper's room (walls and floor) from the start");
  cmd->add_option("--overlay", args->overlays,
                  "Show the knee method's overlays from the start (the knee paper's Fig. 3; the "
                  "Display panel toggles them), comma-separated: influence, contact-vertices")
      ->delimiter(',')
      ->check(CLI::IsMember({"influence", "contact-vertices"}));
  cmd->add_option("--screenshot", args->screenshot, "Write the last frame to FILE.png");
  cmd->add_option("--first-screenshot", args->first_screenshot,
                  "Write an early frame (the scene at rest) to FILE.png");
  cmd->add_option("--json", args->json, "Write fps, haptic loop figures and forces as JSON");
  cmd->add_flag("-q,--quiet", args->quiet, "No summary lines");
  cmd->callback([args] { view(*args); });
}

}  // namespace hapsim::app
