#include "hapsim/render/stereo.h"

#include "hapsim/core/error.h"
#include "hapsim/render/gl_api.h"
#include "hapsim/render/renderer.h"

namespace hapsim {

StereoMode parse_stereo_mode(const std::string& name) {
  if (name == "off") {
    return StereoMode::kOff;
  }
  if (name == "side-by-side") {
    return StereoMode::kSideBySide;
  }
  if (name == "anaglyph") {
    return StereoMode::kAnaglyph;
  }
  throw Error("--stereo", "expected off, side-by-side or anaglyph, got '" + name + "'");
}

const char* to_string(StereoMode mode) {
  switch (mode) {
    case StereoMode::kOff:
      return "off";
    case StereoMode::kSideBySide:
      return "side-by-side";
    case StereoMode::kAnaglyph:
      return "anaglyph";
  }
  return "off";
}

double default_eye_separation_m(const OrbitCamera& camera) {
  return camera.distance_m / 30.0;
}

OrbitCamera eye_camera(const OrbitCamera& camera, double eye_separation_m, int side) {
  const Vec3 eye = camera.eye_world() + (0.5 * side * eye_separation_m) * camera.right_world();
  return OrbitCamera::looking_at(eye, camera.target_world, camera.fov_y_rad);
}

void draw_stereo(Renderer& renderer, const RenderScene& scene, const OrbitCamera& camera,
                 StereoMode mode, double eye_separation_m, int x_px, int y_px, int width_px,
                 int height_px) {
  const double sep = eye_separation_m > 0.0 ? eye_separation_m : default_eye_separation_m(camera);
  switch (mode) {
    case StereoMode::kOff:
      renderer.draw_in(scene, camera, x_px, y_px, width_px, height_px);
      return;
    case StereoMode::kSideBySide: {
      const int half = width_px / 2;
      renderer.draw_in(scene, eye_camera(camera, sep, -1), x_px, y_px, half, height_px);
      renderer.draw_in(scene, eye_camera(camera, sep, +1), x_px + half, y_px, width_px - half,
                       height_px);
      return;
    }
    case StereoMode::kAnaglyph:
      // Each pass clears and draws only its channels (glClear honours the colour mask).
      glColorMask(GL_TRUE, GL_FALSE, GL_FALSE, GL_TRUE);
      renderer.draw_in(scene, eye_camera(camera, sep, -1), x_px, y_px, width_px, height_px);
      glColorMask(GL_FALSE, GL_TRUE, GL_TRUE, GL_TRUE);
      renderer.draw_in(scene, eye_camera(camera, sep, +1), x_px, y_px, width_px, height_px);
      glColorMask(GL_TRUE, GL_TRUE, GL_TRUE, GL_TRUE);
      return;
  }
}

}  // namespace hapsim
