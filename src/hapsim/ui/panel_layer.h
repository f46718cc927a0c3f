// The viewer's panels drawn once into a texture and copied into each frame (issue 13, viewer fps):
// on Mesa's software rasteriser drawing ImGui's ~3k textured, blended triangles cost ~4 ms of CPU
// a frame, a quarter of the knee's frame, while the copy of two panel rectangles is a memory copy.
// The panels are drawn again when someone uses them (every frame then, popups included: drawn
// straight into the window) and otherwise at most `refresh_s` apart, so their figures stay current
// to the eye while the 3D view runs at full rate. Pixels are the same as drawn directly: the panels
// have no background of their own (the clear colour is theirs), and the texture is cleared to it.
#pragma once

#include <cstdint>

namespace hapsim {

/// When the panels must be drawn anew rather than copied from the last drawing.
struct PanelRedrawInput {
  /// Someone is using the panels (ImGui wants the mouse or keyboard, a popup is open): drawn
  /// straight into the window, every frame.
  bool interacting = false;
  /// A picture of this frame is taken (screenshot): its panels show this frame's figures.
  bool picture_due = false;
  /// Seconds since the panels were last drawn (any negative: never drawn at this size).
  double since_drawn_s = -1.0;
  double refresh_s = 0.05;
};

enum class PanelDraw : std::uint8_t {
  kDirect,   // straight into the window (the texture goes stale)
  kRefresh,  // into the texture, then copied
  kCopy,     // the texture as it is
};

[[nodiscard]] PanelDraw choose_panel_draw(const PanelRedrawInput& in);

/// The texture (a framebuffer object the window's size) and the copy. Needs a current GL 3.3
/// context; all calls on that context's thread.
class PanelLayer {
 public:
  PanelLayer() = default;
  ~PanelLayer();
  PanelLayer(const PanelLayer&) = delete;
  PanelLayer& operator=(const PanelLayer&) = delete;
  PanelLayer(PanelLayer&&) = delete;
  PanelLayer& operator=(PanelLayer&&) = delete;

  /// Binds the texture for drawing (made or remade at width×height) and clears it to `rgb`.
  void begin_drawing(int width_px, int height_px, const float rgb[3]);
  /// Back to the window's framebuffer.
  void end_drawing();
  /// Copies the rectangle (GL's window coordinates: origin bottom left) from the texture into the
  /// window's back buffer. Nothing when the texture was never drawn.
  void copy_to_window(int x_px, int y_px, int width_px, int height_px) const;
  /// Whether the texture holds a drawing at width×height.
  [[nodiscard]] bool holds(int width_px, int height_px) const {
    return framebuffer_ != 0 && width_px == width_px_ && height_px == height_px_;
  }

 private:
  void release();

  unsigned framebuffer_ = 0;
  unsigned texture_ = 0;
  int width_px_ = 0;
  int height_px_ = 0;
};

}  // namespace hapsim
