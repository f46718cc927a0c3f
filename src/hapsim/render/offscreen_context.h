// A headless OpenGL 3.3 core context (EGL surfaceless, Mesa llvmpipe on machines without a GPU)
// with its own framebuffer: the renderer draws into it and read_rgba() returns the pixels. Used by
// tests, `hapsim` screenshots and CI, where there is no display and no X server.
#pragma once

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

namespace hapsim {

class OffscreenContext {
 public:
  /// Creates the context, makes it current on this thread and binds a width×height framebuffer
  /// (RGBA8 colour + 24-bit depth) for drawing. `samples` > 1 asks for multisampling (resolved
  /// in read_rgba()); it falls back to a single sample where the driver has fewer.
  /// Throws hapsim::Error naming the step that failed (no EGL display, no GL 3.3 core, …).
  OffscreenContext(int width_px, int height_px, int samples = 4);
  ~OffscreenContext();
  OffscreenContext(const OffscreenContext&) = delete;
  OffscreenContext& operator=(const OffscreenContext&) = delete;

  [[nodiscard]] int width() const;
  [[nodiscard]] int height() const;
  /// Samples per pixel actually in use (1 = no multisampling).
  [[nodiscard]] int samples() const;
  /// GL_RENDERER, e.g. "llvmpipe (LLVM 15.0.6, 256 bits)".
  [[nodiscard]] std::string renderer_name() const;

  /// Makes this context current on the calling thread and binds its framebuffer for drawing.
  void make_current();

  /// The framebuffer as RGBA8, top row first (image order, as PNG files store it), after
  /// glFinish. The second form reuses `rgba`'s storage (no allocation once it is large enough).
  [[nodiscard]] std::vector<std::uint8_t> read_rgba();
  void read_rgba(std::vector<std::uint8_t>& rgba);

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace hapsim
