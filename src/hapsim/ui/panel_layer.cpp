#include "hapsim/ui/panel_layer.h"

#include "hapsim/core/error.h"

// Framebuffer objects without a loader (glvnd's libOpenGL exports the core functions).
#define GL_GLEXT_PROTOTYPES
#include <GL/glcorearb.h>

#include <string>

namespace hapsim {

PanelDraw choose_panel_draw(const PanelRedrawInput& in) {
  if (in.interacting) {
    return PanelDraw::kDirect;
  }
  if (in.picture_due || in.since_drawn_s < 0.0 || in.since_drawn_s >= in.refresh_s) {
    return PanelDraw::kRefresh;
  }
  return PanelDraw::kCopy;
}

PanelLayer::~PanelLayer() {
  release();
}

void PanelLayer::release() {
  if (framebuffer_ != 0) {
    glDeleteFramebuffers(1, &framebuffer_);
    glDeleteTextures(1, &texture_);
  }
  framebuffer_ = 0;
  texture_ = 0;
  width_px_ = 0;
  height_px_ = 0;
}

void PanelLayer::begin_drawing(int width_px, int height_px, const float rgb[3]) {
  if (!holds(width_px, height_px)) {
    release();
    glGenTextures(1, &texture_);
    glBindTexture(GL_TEXTURE_2D, texture_);
    glTexImage2D(GL_TEXTURE_2D, 0, GL_RGBA8, width_px, height_px, 0, GL_RGBA, GL_UNSIGNED_BYTE,
                 nullptr);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MIN_FILTER, GL_NEAREST);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAG_FILTER, GL_NEAREST);
    glBindTexture(GL_TEXTURE_2D, 0);
    glGenFramebuffers(1, &framebuffer_);
    glBindFramebuffer(GL_FRAMEBUFFER, framebuffer_);
    glFramebufferTexture2D(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, GL_TEXTURE_2D, texture_, 0);
    const GLenum status = glCheckFramebufferStatus(GL_FRAMEBUFFER);
    if (status != GL_FRAMEBUFFER_COMPLETE) {
      glBindFramebuffer(GL_FRAMEBUFFER, 0);
      release();
      throw Error("viewer", "the panels' framebuffer is incomplete (GL status " +
                                std::to_string(status) + ")");
    }
    width_px_ = width_px;
    height_px_ = height_px;
  }
  glBindFramebuffer(GL_FRAMEBUFFER, framebuffer_);
  glViewport(0, 0, width_px, height_px);
  glDisable(GL_SCISSOR_TEST);
  glClearColor(rgb[0], rgb[1], rgb[2], 1.0f);
  glClear(GL_COLOR_BUFFER_BIT);
}

void PanelLayer::end_drawing() {
  glBindFramebuffer(GL_FRAMEBUFFER, 0);
}

void PanelLayer::copy_to_window(int x_px, int y_px, int width_px, int height_px) const {
  if (framebuffer_ == 0 || width_px <= 0 || height_px <= 0) {
    return;
  }
  // Same size, same format, no scissor: Mesa copies the memory (no drawing).
  glBindFramebuffer(GL_READ_FRAMEBUFFER, framebuffer_);
  glBindFramebuffer(GL_DRAW_FRAMEBUFFER, 0);
  glDisable(GL_SCISSOR_TEST);
  glBlitFramebuffer(x_px, y_px, x_px + width_px, y_px + height_px, x_px, y_px, x_px + width_px,
                    y_px + height_px, GL_COLOR_BUFFER_BIT, GL_NEAREST);
  glBindFramebuffer(GL_READ_FRAMEBUFFER, 0);
}

}  // namespace hapsim
