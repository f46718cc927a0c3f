#include "hapsim/render/snapshot_writer.h"

#include "hapsim/core/error.h"
#include "hapsim/render/offscreen_context.h"
#include "hapsim/render/png_image.h"
#include "hapsim/render/renderer.h"

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <numbers>
#include <string>
#include <vector>

namespace hapsim {

SnapshotWriter::SnapshotWriter(int width_px, int height_px, int samples)
    : width_px_(width_px), height_px_(height_px) {
  if (width_px < 16 || height_px < 16 || width_px > 8192 || height_px > 8192) {
    throw Error("snapshot", "size must be between 16x16 and 8192x8192 pixels, got " +
                                std::to_string(width_px) + "x" + std::to_string(height_px));
  }
  context_ = std::make_unique<OffscreenContext>(width_px, height_px, samples);
  renderer_ = std::make_unique<Renderer>();
}

SnapshotWriter::~SnapshotWriter() {
  if (context_) {
    try {
      context_->make_current();  // the renderer frees its GL objects in its own context
    } catch (...) {
      // A context that cannot be made current any more: its objects go with it.
    }
  }
  renderer_.reset();
  context_.reset();
}

const std::vector<std::uint8_t>& SnapshotWriter::render(const RenderScene& scene,
                                                        const OrbitCamera& camera) {
  context_->make_current();
  draw_stereo(*renderer_, scene, camera, stereo_, eye_separation_m_, 0, 0, width_px_, height_px_);
  context_->read_rgba(rgba_);
  return rgba_;
}

void SnapshotWriter::write_png(const RenderScene& scene, const OrbitCamera& camera,
                               const std::string& path) {
  hapsim::write_png(path, width_px_, height_px_, render(scene, camera));
}

int SnapshotWriter::samples() const {
  return context_->samples();
}

std::string SnapshotWriter::renderer_name() const {
  return context_->renderer_name();
}

OrbitCamera framed_camera(const Box3& bounds_world, double aspect, double yaw_rad, double pitch_rad,
                          double margin) {
  OrbitCamera camera;
  camera.yaw_rad = yaw_rad;
  camera.pitch_rad = pitch_rad;
  if (!bounds_world.isEmpty()) {
    camera.frame(bounds_world, aspect, margin);
  }
  return camera;
}

OrbitCamera parse_camera_spec(const std::string& spec) {
  const std::string usage =
      "expected EX,EY,EZ,TX,TY,TZ,FOV (eye and target in metres, field of view in degrees), got "
      "'" +
      spec + "'";
  std::vector<double> v;
  std::size_t start = 0;
  while (start <= spec.size()) {
    const std::size_t comma = std::min(spec.find(',', start), spec.size());
    const std::string item = spec.substr(start, comma - start);
    std::size_t used = 0;
    double x = 0.0;
    try {
      x = std::stod(item, &used);
    } catch (const std::exception&) {
      throw Error("--camera", usage);
    }
    if (used != item.size() || !std::isfinite(x)) {
      throw Error("--camera", usage);
    }
    v.push_back(x);
    start = comma + 1;
  }
  if (v.size() != 7) {
    throw Error("--camera", usage);
  }
  const Vec3 eye(v[0], v[1], v[2]);
  const Vec3 target(v[3], v[4], v[5]);
  if (!(v[6] > 1.0 && v[6] <= 170.0)) {
    throw Error("--camera", "field of view must be in (1, 170] degrees, got " + spec);
  }
  if ((eye - target).norm() < 1e-6) {
    throw Error("--camera", "the eye is on its target: " + spec);
  }
  return OrbitCamera::looking_at(eye, target, v[6] * std::numbers::pi / 180.0);
}

std::optional<OrbitCamera> chosen_camera(const SceneDescription& scene, const std::string& view,
                                         const std::string& camera_spec) {
  if (!view.empty() && !camera_spec.empty()) {
    throw Error("--view and --camera", "give one of them");
  }
  if (!camera_spec.empty()) {
    return parse_camera_spec(camera_spec);
  }
  if (view.empty()) {
    return std::nullopt;
  }
  std::string names;
  for (const SceneView& v : scene.views) {
    if (v.name == view) {
      return OrbitCamera::looking_at(v.eye_m, v.target_m, v.fov_deg * std::numbers::pi / 180.0);
    }
    names += (names.empty() ? "" : ", ") + v.name;
  }
  throw Error(scene.file.string(),
              "--view " + view + ": the scene has " +
                  (names.empty() ? std::string("no views") : "the views " + names));
}

std::string numbered_path(const std::string& path, std::uint64_t index) {
  const std::filesystem::path p(path);
  char suffix[32];
  std::snprintf(suffix, sizeof suffix, "_%06llu", static_cast<unsigned long long>(index));
  return (p.parent_path() / (p.stem().string() + suffix + p.extension().string())).string();
}

DisplayMode parse_display_mode(const std::string& name) {
  if (name == "points") {
    return DisplayMode::kPoints;
  }
  if (name == "lines") {
    return DisplayMode::kLines;
  }
  if (name == "faces") {
    return DisplayMode::kFaces;
  }
  throw Error("display mode", "expected points, lines or faces, got '" + name + "'");
}

const char* to_string(DisplayMode mode) {
  switch (mode) {
    case DisplayMode::kPoints:
      return "points";
    case DisplayMode::kLines:
      return "lines";
    case DisplayMode::kFaces:
      return "faces";
  }
  return "faces";
}

}  // namespace hapsim
