// Presents a rectangle of the window's back buffer without swapping buffers
// (GLX_MESA_copy_sub_buffer), so the rest of the back buffer keeps what was drawn there: the viewer
// redraws and presents only its 3D view while the panels are unchanged (ui/panel_refresh.h).
// A swap would leave the back buffer's contents undefined; a copy never touches them.
#pragma once

#include <optional>

namespace hapsim {

class SubBufferPresenter {
 public:
  /// For the current context's drawable; none when the context is not GLX (Wayland, EGL) or the
  /// driver lacks the extension (it is Mesa's: llvmpipe under Xvfb or X11 has it).
  /// Precondition: a context is current on this thread.
  static std::optional<SubBufferPresenter> for_current_context();

  /// Copies the rectangle to the window: GL window coordinates (pixels, origin bottom left).
  /// Flushes GL first, as a swap does. Call on the context's thread.
  void present(int x_px, int y_px, int width_px, int height_px) const;

 private:
  // X11's types stay out of this header (its macros, None and Bool among them, break other code):
  // the Display*, the GLXDrawable and glXCopySubBufferMESA, cast back in the .cpp.
  void* display_ = nullptr;
  unsigned long drawable_ = 0;
  void (*copy_)() = nullptr;
};

}  // namespace hapsim
