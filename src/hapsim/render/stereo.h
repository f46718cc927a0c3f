// Stereo pictures (the knee paper's future work, SPEC §11): the scene drawn for a left and a right
// eye either side by side (cross-free parallel viewing, or a 3D monitor's side-by-side input) or
// as a red–cyan anaglyph (left eye in the red channel, right eye in green and blue: red–cyan
// glasses). The eyes sit half the separation either side of the camera's eye along its right
// axis, both looking at its target (toe-in), with its field of view.
#pragma once

#include "hapsim/render/camera.h"
#include "hapsim/render/render_scene.h"

#include <string>

namespace hapsim {

class Renderer;

enum class StereoMode { kOff, kSideBySide, kAnaglyph };

/// "off" | "side-by-side" | "anaglyph"; throws hapsim::Error naming the choices otherwise.
[[nodiscard]] StereoMode parse_stereo_mode(const std::string& name);
[[nodiscard]] const char* to_string(StereoMode mode);

/// The default separation of the eyes: a thirtieth of the distance to the target (the usual
/// stereographers' rule: depth without strain at any scale).
[[nodiscard]] double default_eye_separation_m(const OrbitCamera& camera);

/// The camera of one eye: side −1 left, +1 right.
[[nodiscard]] OrbitCamera eye_camera(const OrbitCamera& camera, double eye_separation_m, int side);

/// Draws `scene` into the viewport (x, y, width, height) as `mode` asks (kOff: one picture).
/// `eye_separation_m` ≤ 0: default_eye_separation_m. Leaves the colour mask as it found it (all
/// channels).
void draw_stereo(Renderer& renderer, const RenderScene& scene, const OrbitCamera& camera,
                 StereoMode mode, double eye_separation_m, int x_px, int y_px, int width_px,
                 int height_px);

}  // namespace hapsim
