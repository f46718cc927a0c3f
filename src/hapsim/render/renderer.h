// Draws a RenderScene with OpenGL 3.3 core into the currently bound framebuffer: an
// OffscreenContext for tests and screenshots, a GLFW window's back buffer in the viewer (buffer
// swapping is the window's job). Shading is Gouraud: lighting (ambient + Lambert diffuse +
// Blinn-Phong specular, several directional lights) is computed per VERTEX and interpolated
// across triangles, both sides lit so open sheets look right from below.
#pragma once

#include "hapsim/render/camera.h"
#include "hapsim/render/render_scene.h"

#include <cstddef>
#include <memory>
#include <string>

namespace hapsim {

/// What the last draw drew (a stereo pair: its last eye).
struct RenderStats {
  /// Mesh triangles drawn, at the levels of detail chosen.
  std::size_t triangles_drawn = 0;
  /// The same meshes' triangles at full detail.
  std::size_t triangles_full = 0;
  /// Meshes drawn at a coarser level than the full mesh.
  std::size_t meshes_coarser = 0;
};

class Renderer {
 public:
  /// Needs a current OpenGL ≥ 3.3 core context; compiles the shaders and builds the shared
  /// sphere mesh. Throws hapsim::Error if there is no context or a shader fails to build.
  /// Destroy the Renderer while its context is still alive and current.
  Renderer();
  ~Renderer();
  Renderer(const Renderer&) = delete;
  Renderer& operator=(const Renderer&) = delete;

  /// Clears to the scene's background and draws one frame into the bound framebuffer, over a
  /// viewport of width_px × height_px. Meshes are uploaded on first sight and re-uploaded when
  /// their stamps change; otherwise per-frame work reuses buffers (no allocation once warm).
  /// One Renderer is meant to draw one scene (GPU copies are kept per mesh id).
  void draw(const RenderScene& scene, const OrbitCamera& camera, int width_px, int height_px);
  /// The same into the viewport whose lower-left corner is (x_px, y_px) in GL window
  /// coordinates (y up); only that rectangle is cleared (a window draws panels around it).
  void draw_in(const RenderScene& scene, const OrbitCamera& camera, int x_px, int y_px,
               int width_px, int height_px);

  [[nodiscard]] const RenderStats& last_frame_stats() const;

  /// "4.5 (Core Profile) Mesa 22.3.6" etc., for logs.
  [[nodiscard]] std::string gl_version() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace hapsim
