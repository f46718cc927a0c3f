#include "hapsim/render/offscreen_context.h"

#include "hapsim/core/error.h"
#include "hapsim/core/leak_check.h"
#include "hapsim/render/gl_api.h"

// No X11 types in the EGL headers: this context never talks to a display server.
#define EGL_NO_X11 1
#define MESA_EGL_NO_X11_HEADERS 1
#include <EGL/egl.h>
#include <EGL/eglext.h>

#include <algorithm>
#include <mutex>
#include <sstream>

namespace hapsim {
namespace {

constexpr const char* kWhere = "OffscreenContext";

std::string egl_error_text() {
  std::ostringstream os;
  os << "EGL error 0x" << std::hex << eglGetError();
  return os.str();
}

// EGL displays are per process, and eglTerminate() ends every context on one; count users so the
// last OffscreenContext to go terminates it.
std::mutex g_display_mutex;
int g_display_users = 0;
EGLDisplay g_display = EGL_NO_DISPLAY;

EGLDisplay acquire_surfaceless_display() {
  const std::lock_guard<std::mutex> lock(g_display_mutex);
  if (g_display_users > 0) {
    ++g_display_users;
    return g_display;
  }
  EGLDisplay display = EGL_NO_DISPLAY;
  // EGL 1.5 has eglGetPlatformDisplay; older loaders only the EXT entry point.
  display = eglGetPlatformDisplay(EGL_PLATFORM_SURFACELESS_MESA, EGL_DEFAULT_DISPLAY, nullptr);
  if (display == EGL_NO_DISPLAY) {
    const auto get_platform_display_ext = reinterpret_cast<PFNEGLGETPLATFORMDISPLAYEXTPROC>(
        eglGetProcAddress("eglGetPlatformDisplayEXT"));
    if (get_platform_display_ext != nullptr) {
      display =
          get_platform_display_ext(EGL_PLATFORM_SURFACELESS_MESA, EGL_DEFAULT_DISPLAY, nullptr);
    }
  }
  if (display == EGL_NO_DISPLAY) {
    throw Error(kWhere, "EGL: no surfaceless display (is libgl1-mesa-dri installed?)");
  }
  EGLint major = 0;
  EGLint minor = 0;
  if (eglInitialize(display, &major, &minor) != EGL_TRUE) {
    throw Error(kWhere, "EGL: eglInitialize failed on the surfaceless display (" +
                            egl_error_text() + "; is libgl1-mesa-dri installed?)");
  }
  g_display = display;
  g_display_users = 1;
  return display;
}

void release_display() {
  const std::lock_guard<std::mutex> lock(g_display_mutex);
  if (--g_display_users == 0) {
    eglTerminate(g_display);
    g_display = EGL_NO_DISPLAY;
  }
}

}  // namespace

struct OffscreenContext::Impl {
  int width = 0;
  int height = 0;
  int samples = 1;
  EGLDisplay display = EGL_NO_DISPLAY;
  EGLContext context = EGL_NO_CONTEXT;
  // Drawn into (multisampled when samples > 1).
  GLuint draw_fbo = 0;
  GLuint draw_colour = 0;
  GLuint draw_depth = 0;
  // Single-sample target of the resolve blit; 0 when draw_fbo is single-sample.
  GLuint resolve_fbo = 0;
  GLuint resolve_colour = 0;

  void release() {
    if (context != EGL_NO_CONTEXT) {
      eglMakeCurrent(display, EGL_NO_SURFACE, EGL_NO_SURFACE, context);
      const GLuint fbos[] = {draw_fbo, resolve_fbo};
      glDeleteFramebuffers(2, fbos);
      const GLuint rbos[] = {draw_colour, draw_depth, resolve_colour};
      glDeleteRenderbuffers(3, rbos);
      eglMakeCurrent(display, EGL_NO_SURFACE, EGL_NO_SURFACE, EGL_NO_CONTEXT);
      eglDestroyContext(display, context);
      context = EGL_NO_CONTEXT;
    }
    if (display != EGL_NO_DISPLAY) {
      release_display();
      display = EGL_NO_DISPLAY;
    }
  }
};

namespace {

GLuint make_renderbuffer(int samples, GLenum format, int width, int height) {
  GLuint rbo = 0;
  glGenRenderbuffers(1, &rbo);
  glBindRenderbuffer(GL_RENDERBUFFER, rbo);
  if (samples > 1) {
    glRenderbufferStorageMultisample(GL_RENDERBUFFER, samples, format, width, height);
  } else {
    glRenderbufferStorage(GL_RENDERBUFFER, format, width, height);
  }
  return rbo;
}

void check_framebuffer(const char* which) {
  const GLenum status = glCheckFramebufferStatus(GL_FRAMEBUFFER);
  if (status != GL_FRAMEBUFFER_COMPLETE) {
    std::ostringstream os;
    os << "GL: " << which << " framebuffer incomplete (status 0x" << std::hex << status << ")";
    throw Error(kWhere, os.str());
  }
}

}  // namespace

OffscreenContext::OffscreenContext(int width_px, int height_px, int samples)
    : impl_(std::make_unique<Impl>()) {
  Impl& s = *impl_;
  if (width_px <= 0 || height_px <= 0) {
    throw Error(kWhere, "size must be positive, got " + std::to_string(width_px) + "x" +
                            std::to_string(height_px));
  }
  s.width = width_px;
  s.height = height_px;
  try {
    s.display = acquire_surfaceless_display();
    if (eglBindAPI(EGL_OPENGL_API) != EGL_TRUE) {
      throw Error(kWhere, "EGL: desktop OpenGL API not available (" + egl_error_text() + ")");
    }
    // Any OpenGL-capable config; the surfaceless platform draws only into FBOs. Without one, a
    // config-less context (EGL_KHR_no_config_context) does the same job.
    const EGLint config_attribs[] = {EGL_RENDERABLE_TYPE, EGL_OPENGL_BIT, EGL_NONE};
    EGLConfig config = nullptr;
    EGLint config_count = 0;
    if (eglChooseConfig(s.display, config_attribs, &config, 1, &config_count) != EGL_TRUE ||
        config_count == 0) {
      config = nullptr;  // == EGL_NO_CONFIG_KHR
    }
    const EGLint context_attribs[] = {EGL_CONTEXT_MAJOR_VERSION,
                                      3,
                                      EGL_CONTEXT_MINOR_VERSION,
                                      3,
                                      EGL_CONTEXT_OPENGL_PROFILE_MASK,
                                      EGL_CONTEXT_OPENGL_CORE_PROFILE_BIT,
                                      EGL_NONE};
    s.context = eglCreateContext(s.display, config, EGL_NO_CONTEXT, context_attribs);
    if (s.context == EGL_NO_CONTEXT) {
      throw Error(kWhere,
                  "EGL: cannot create an OpenGL 3.3 core context (" + egl_error_text() + ")");
    }
    if (eglMakeCurrent(s.display, EGL_NO_SURFACE, EGL_NO_SURFACE, s.context) != EGL_TRUE) {
      throw Error(kWhere,
                  "EGL: cannot make the surfaceless context current (" + egl_error_text() + ")");
    }
    keep_libraries_mapped_for_leak_check();  // Mesa's driver is loaded by now

    GLint max_samples = 1;
    glGetIntegerv(GL_MAX_SAMPLES, &max_samples);
    s.samples = samples > 1 ? std::min(samples, static_cast<int>(max_samples)) : 1;
    if (s.samples < 2) {
      s.samples = 1;
    }

    s.draw_colour = make_renderbuffer(s.samples, GL_RGBA8, s.width, s.height);
    s.draw_depth = make_renderbuffer(s.samples, GL_DEPTH_COMPONENT24, s.width, s.height);
    glGenFramebuffers(1, &s.draw_fbo);
    glBindFramebuffer(GL_FRAMEBUFFER, s.draw_fbo);
    glFramebufferRenderbuffer(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, GL_RENDERBUFFER, s.draw_colour);
    glFramebufferRenderbuffer(GL_FRAMEBUFFER, GL_DEPTH_ATTACHMENT, GL_RENDERBUFFER, s.draw_depth);
    check_framebuffer("drawing");
    if (s.samples > 1) {
      s.resolve_colour = make_renderbuffer(1, GL_RGBA8, s.width, s.height);
      glGenFramebuffers(1, &s.resolve_fbo);
      glBindFramebuffer(GL_FRAMEBUFFER, s.resolve_fbo);
      glFramebufferRenderbuffer(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, GL_RENDERBUFFER,
                                s.resolve_colour);
      check_framebuffer("resolve");
    }
    glBindFramebuffer(GL_FRAMEBUFFER, s.draw_fbo);
    glViewport(0, 0, s.width, s.height);
  } catch (...) {
    s.release();
    throw;
  }
}

OffscreenContext::~OffscreenContext() {
  impl_->release();
}

int OffscreenContext::width() const {
  return impl_->width;
}
int OffscreenContext::height() const {
  return impl_->height;
}
int OffscreenContext::samples() const {
  return impl_->samples;
}

std::string OffscreenContext::renderer_name() const {
  const auto* name = reinterpret_cast<const char*>(glGetString(GL_RENDERER));
  return name != nullptr ? name : "";
}

void OffscreenContext::make_current() {
  if (eglMakeCurrent(impl_->display, EGL_NO_SURFACE, EGL_NO_SURFACE, impl_->context) != EGL_TRUE) {
    throw Error(kWhere, "EGL: eglMakeCurrent failed (" + egl_error_text() + ")");
  }
  glBindFramebuffer(GL_FRAMEBUFFER, impl_->draw_fbo);
}

std::vector<std::uint8_t> OffscreenContext::read_rgba() {
  std::vector<std::uint8_t> rgba;
  read_rgba(rgba);
  return rgba;
}

void OffscreenContext::read_rgba(std::vector<std::uint8_t>& rgba) {
  const Impl& s = *impl_;
  const auto row_bytes = static_cast<std::size_t>(s.width) * 4;
  rgba.resize(row_bytes * static_cast<std::size_t>(s.height));
  while (glGetError() != GL_NO_ERROR) {
    // Errors left by earlier drawing are not this read's; drop them so the check below is ours.
  }
  GLuint read_fbo = s.draw_fbo;
  if (s.samples > 1) {
    // Multisampled pixels cannot be read directly: average the samples into the resolve target.
    glBindFramebuffer(GL_READ_FRAMEBUFFER, s.draw_fbo);
    glBindFramebuffer(GL_DRAW_FRAMEBUFFER, s.resolve_fbo);
    glBlitFramebuffer(0, 0, s.width, s.height, 0, 0, s.width, s.height, GL_COLOR_BUFFER_BIT,
                      GL_NEAREST);
    read_fbo = s.resolve_fbo;
  }
  glBindFramebuffer(GL_READ_FRAMEBUFFER, read_fbo);
  glPixelStorei(GL_PACK_ALIGNMENT, 1);
  glReadPixels(0, 0, s.width, s.height, GL_RGBA, GL_UNSIGNED_BYTE, rgba.data());
  glBindFramebuffer(GL_FRAMEBUFFER, s.draw_fbo);
  const GLenum error = glGetError();
  if (error != GL_NO_ERROR) {
    std::ostringstream os;
    os << "GL: reading the framebuffer failed (error 0x" << std::hex << error << ")";
    throw Error(kWhere, os.str());
  }
  // GL's rows run bottom-up; images run top-down.
  for (int y = 0; y < s.height / 2; ++y) {
    auto top = rgba.begin() + static_cast<std::ptrdiff_t>(row_bytes) * y;
    auto bottom = rgba.begin() + static_cast<std::ptrdiff_t>(row_bytes) * (s.height - 1 - y);
    std::swap_ranges(top, top + static_cast<std::ptrdiff_t>(row_bytes), bottom);
  }
}

}  // namespace hapsim
