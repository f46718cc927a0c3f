// Pictures with no display (architecture.md#viewer "headless rendering to PNG"): an offscreen
// context and a renderer that draw a RenderScene from a camera and write a PNG, for `hapsim run
// --snapshot`, reference-image tests, reports and CI.
#pragma once

#include "hapsim/render/camera.h"
#include "hapsim/render/render_scene.h"
#include "hapsim/render/stereo.h"
#include "hapsim/scene/scene_description.h"

#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <vector>

namespace hapsim {

class OffscreenContext;
class Renderer;

class SnapshotWriter {
 public:
  /// Creates the offscreen context (EGL surfaceless) and the renderer. `samples` > 1 smooths
  /// edges (4x costs ~2.6x the time on Mesa's software rasteriser). Throws hapsim::Error when no
  /// context can be made.
  SnapshotWriter(int width_px, int height_px, int samples = 4);
  ~SnapshotWriter();
  SnapshotWriter(const SnapshotWriter&) = delete;
  SnapshotWriter& operator=(const SnapshotWriter&) = delete;
  SnapshotWriter(SnapshotWriter&&) = delete;
  SnapshotWriter& operator=(SnapshotWriter&&) = delete;

  /// Stereo pictures from now on (stereo.h): side by side or red–cyan anaglyph; separation ≤ 0:
  /// the default for the camera's distance.
  void set_stereo(StereoMode mode, double eye_separation_m) {
    stereo_ = mode;
    eye_separation_m_ = eye_separation_m;
  }

  /// Draws `scene` from `camera` and returns the pixels (RGBA8, top row first).
  const std::vector<std::uint8_t>& render(const RenderScene& scene, const OrbitCamera& camera);
  /// Draws and writes a PNG; throws hapsim::Error naming `path` when it cannot be written.
  void write_png(const RenderScene& scene, const OrbitCamera& camera, const std::string& path);

  [[nodiscard]] int width() const { return width_px_; }
  [[nodiscard]] int height() const { return height_px_; }
  [[nodiscard]] std::string renderer_name() const;
  /// Samples per pixel in use (1: no multisampling).
  [[nodiscard]] int samples() const;

 private:
  int width_px_;
  int height_px_;
  std::unique_ptr<OffscreenContext> context_;
  std::unique_ptr<Renderer> renderer_;
  std::vector<std::uint8_t> rgba_;
  StereoMode stereo_ = StereoMode::kOff;
  double eye_separation_m_ = 0.0;
};

/// A camera looking at the centre of `bounds_world` from azimuth `yaw_rad` and elevation
/// `pitch_rad`, close enough to show the whole box in a viewport of `aspect`.
[[nodiscard]] OrbitCamera framed_camera(const Box3& bounds_world, double aspect, double yaw_rad,
                                        double pitch_rad, double margin = 1.05);

/// "EX,EY,EZ,TX,TY,TZ,FOV": the eye and the target (world, metres) and the vertical field of view
/// (degrees, in (1, 170]) of `--camera`; throws hapsim::Error saying what is wrong otherwise.
[[nodiscard]] OrbitCamera parse_camera_spec(const std::string& spec);

/// The camera `--view NAME` (one of `scene.views`) or `--camera SPEC` (parse_camera_spec) chose,
/// none when both are empty: `hapsim run`/`watch` snapshots and the viewer's first camera. Throws
/// hapsim::Error (one line) for both at once, a bad spec, or a view the scene does not have
/// (naming the scene's file and the views it has).
[[nodiscard]] std::optional<OrbitCamera> chosen_camera(const SceneDescription& scene,
                                                       const std::string& view,
                                                       const std::string& camera_spec);

/// "out.png", 42 → "out_000042.png" (a series of snapshots).
[[nodiscard]] std::string numbered_path(const std::string& path, std::uint64_t index);

/// Parses "points" | "lines" | "faces"; throws hapsim::Error otherwise.
[[nodiscard]] DisplayMode parse_display_mode(const std::string& name);
[[nodiscard]] const char* to_string(DisplayMode mode);

}  // namespace hapsim
