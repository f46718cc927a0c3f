// hapsim_x11_grab OUT.png: what the X server shows on its root window, as a PNG. The viewer tests
// use it to see the window as the user does (GL cannot read back what a window shows on Mesa's
// software rasteriser: its front buffer reads black). Needs a 24- or 32-bit TrueColor screen
// (Xvfb -screen 0 WxHx24).
#include "hapsim/render/png_image.h"

#include <X11/Xlib.h>
#include <X11/Xutil.h>

#include <cstdint>
#include <cstdio>
#include <exception>
#include <vector>

namespace {

// The shift that brings a channel's mask down to its lowest bit.
int shift_of(unsigned long mask) {
  int shift = 0;
  while (mask != 0 && (mask & 1UL) == 0) {
    mask >>= 1;
    ++shift;
  }
  return shift;
}

}  // namespace

int main(int argc, char** argv) {
  if (argc != 2) {
    std::fprintf(stderr, "usage: hapsim_x11_grab OUT.png\n");
    return 2;
  }
  Display* display = XOpenDisplay(nullptr);
  if (display == nullptr) {
    std::fprintf(stderr, "hapsim_x11_grab: cannot open the display (DISPLAY unset?)\n");
    return 1;
  }
  const Window root = DefaultRootWindow(display);
  XWindowAttributes attributes{};
  XGetWindowAttributes(display, root, &attributes);
  XImage* image = XGetImage(display, root, 0, 0, static_cast<unsigned>(attributes.width),
                            static_cast<unsigned>(attributes.height), AllPlanes, ZPixmap);
  if (image == nullptr || image->bits_per_pixel < 24) {
    std::fprintf(stderr, "hapsim_x11_grab: no 24-bit image of the root window\n");
    XCloseDisplay(display);
    return 1;
  }
  const int w = attributes.width;
  const int h = attributes.height;
  const int rs = shift_of(image->red_mask);
  const int gs = shift_of(image->green_mask);
  const int bs = shift_of(image->blue_mask);
  std::vector<std::uint8_t> rgba(static_cast<std::size_t>(w) * h * 4);
  for (int y = 0; y < h; ++y) {
    for (int x = 0; x < w; ++x) {
      const unsigned long p = XGetPixel(image, x, y);
      std::uint8_t* o = &rgba[(static_cast<std::size_t>(y) * w + x) * 4];
      o[0] = static_cast<std::uint8_t>((p & image->red_mask) >> rs);
      o[1] = static_cast<std::uint8_t>((p & image->green_mask) >> gs);
      o[2] = static_cast<std::uint8_t>((p & image->blue_mask) >> bs);
      o[3] = 255;
    }
  }
  XDestroyImage(image);
  XCloseDisplay(display);
  try {
    hapsim::write_png(argv[1], w, h, rgba);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "hapsim_x11_grab: %s\n", e.what());
    return 1;
  }
  return 0;
}
