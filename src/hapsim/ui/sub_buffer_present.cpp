#include "hapsim/ui/sub_buffer_present.h"

#include <GL/glx.h>

#include <cstring>

namespace hapsim {
namespace {

// GLX_MESA_copy_sub_buffer's entry point.
using CopySubBufferMesa = void (*)(Display* display, GLXDrawable drawable, int x, int y, int width,
                                   int height);

}  // namespace

std::optional<SubBufferPresenter> SubBufferPresenter::for_current_context() {
  Display* display = glXGetCurrentDisplay();
  const GLXDrawable drawable = glXGetCurrentDrawable();
  if (display == nullptr || drawable == 0) {
    return std::nullopt;  // not a GLX context
  }
  const char* extensions = glXQueryExtensionsString(display, DefaultScreen(display));
  if (extensions == nullptr || std::strstr(extensions, "GLX_MESA_copy_sub_buffer") == nullptr) {
    return std::nullopt;
  }
  const auto address = glXGetProcAddressARB(
      reinterpret_cast<const GLubyte*>("glXCopySubBufferMESA"));  // GLX's byte-string API
  if (address == nullptr) {
    return std::nullopt;
  }
  SubBufferPresenter p;
  p.display_ = display;
  p.drawable_ = drawable;
  p.copy_ = address;  // GLX's generic function pointer, cast back in present()
  return p;
}

void SubBufferPresenter::present(int x_px, int y_px, int width_px, int height_px) const {
  const auto copy = reinterpret_cast<CopySubBufferMesa>(copy_);
  copy(static_cast<Display*>(display_), drawable_, x_px, y_px, width_px, height_px);
}

}  // namespace hapsim
