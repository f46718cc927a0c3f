// `hapsim view SCENE` (architecture.md#viewer, issue 5): a window with the 3D view (Gouraud
// shading, lights, point/line/face modes, rotate/pan/zoom, the floor with the tool's 'x' shadow
// mark), a control area (display, scene, device, contact and deformation method, segments,
// stiffness and limits, pause/reset, record), a data area (tool and device coordinates in mm, force
// per finger, haptic rate, step cost, graphics fps) and a force column graph with a scrolling force
// plot, while the scene runs on the real-time haptic thread.
//
// Mouse: left-drag moves the probe in the view plane, the wheel pushes it in or pulls it out;
// right-drag rotates the view, middle-drag (or shift+right) pans, ctrl+wheel zooms.
// Keys: 1-5 curl fingers (glove scenes), G closes/opens the grasp, space pauses, R resets,
// M cycles the display mode, V cycles stereo (off, side by side, anaglyph), F frames the scene,
// C gives the 3D mouse (--device spacemouse) to the camera or back to the probe
// (ui/space_mouse_camera.h), Tab hides the panels, Esc quits.
#pragma once

#include "hapsim/render/stereo.h"
#include "hapsim/ui/viewer_session.h"

#include <atomic>
#include <filesystem>
#include <string>
#include <vector>

namespace hapsim {

struct ViewerOptions {
  ViewerConfig config;
  int width_px = 1280;
  int height_px = 720;
  /// Sync buffer swaps to the display (off: draw as fast as possible, for measuring fps).
  bool vsync = true;
  /// Multisampling (GLFW_SAMPLES): 0 on a software rasteriser, 4 on a GPU.
  int msaa_samples = 0;
  /// Show the control and data areas (Tab toggles them): off gives the 3D view the window.
  bool panels = true;
  /// On a software rasteriser, redraw the panels at least this often while nothing happens on
  /// them, and in the frames between draw and present the 3D view alone (ui/panel_refresh.h);
  /// 0 draws them every frame. On a GPU they are drawn every frame.
  double panel_refresh_hz = 20.0;
  /// Stereo 3D view (render/stereo.h; the V key cycles off / side by side / anaglyph) and the
  /// eyes' separation in metres (0: a thirtieth of the view distance).
  StereoMode stereo = StereoMode::kOff;
  double eye_separation_m = 0.0;
  /// Where the view first looks from: a view named in the scene file's "views" (`view`), or
  /// eye,target,fov given outright (`camera`, as render/snapshot_writer.h's parse_camera_spec
  /// reads it); neither: the scene framed from the front. At most one of them. A scene chosen
  /// later in the scene menu is framed as usual.
  std::string view;
  std::string camera;
  /// Show the knee paper's room (walls and floor) from the start; the data area's "room" box
  /// toggles it.
  bool room = false;
  /// The knee method's overlays from the start (`--overlay influence,contact-vertices`); the
  /// Display panel's boxes toggle them.
  bool influence_overlay = false;
  bool contact_vertices_overlay = false;
  /// Close after this many seconds (0: when the window is closed).
  double duration_s = 0.0;
  /// Close when this becomes true (set by a signal handler: SIGINT/SIGTERM), as if the window
  /// were closed: the haptic loop stops (zero force) and the screenshot and JSON are written.
  const std::atomic<bool>* stop = nullptr;
  /// Write the last frame (the whole window) to this PNG when closing.
  std::filesystem::path screenshot;
  /// Also write the first complete frame here.
  std::filesystem::path first_screenshot;
  /// Write the run's figures (fps, haptic loop, forces) as JSON here.
  std::filesystem::path json;
  /// Scene files offered in the scene menu (the viewer adds the one it was started with).
  std::vector<std::filesystem::path> scene_choices;
  bool quiet = false;
};

/// Opens the window and runs until closed or duration_s. Returns the process exit status (0, or 1
/// when a force above the device rating or a NaN was ever shown). Throws hapsim::Error when no
/// window can be opened (no display) or the first session cannot be built.
int run_viewer(const ViewerOptions& options);

}  // namespace hapsim
