// Shared by the render tests: an offscreen GL context, or the reason there is none (the GL tests
// then GTEST_SKIP with it, on machines where EGL cannot make a context).
#pragma once

#include "hapsim/core/error.h"
#include "hapsim/render/offscreen_context.h"
#include "hapsim/render/renderer.h"

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

namespace hapsim::test {

struct MaybeContext {
  std::unique_ptr<OffscreenContext> context;
  std::string why_not;
};

inline MaybeContext make_test_context(int width, int height, int samples = 1) {
  MaybeContext out;
  try {
    out.context = std::make_unique<OffscreenContext>(width, height, samples);
  } catch (const Error& e) {
    out.why_not = e.what();
  }
  return out;
}

/// One offscreen context and renderer a whole suite shares (creating llvmpipe contexts is not
/// free): opened in SetUpTestSuite, closed in TearDownTestSuite, the renderer before its context.
struct SharedGl {
  std::unique_ptr<OffscreenContext> context;
  std::unique_ptr<Renderer> renderer;
  std::string why_not;

  void open(int width, int height) {
    MaybeContext maybe = make_test_context(width, height, 1);
    why_not = std::move(maybe.why_not);
    context = std::move(maybe.context);
    if (context) {
      renderer = std::make_unique<Renderer>();
    }
  }
  void close() {
    renderer.reset();
    context.reset();
  }
};

/// RGBA of pixel (x, y), y counted from the top.
struct Pixel {
  int r, g, b, a;
};
inline Pixel pixel_at(const std::vector<std::uint8_t>& rgba, int width, int x, int y) {
  const std::size_t i = 4 * (static_cast<std::size_t>(y) * static_cast<std::size_t>(width) +
                             static_cast<std::size_t>(x));
  return {rgba[i], rgba[i + 1], rgba[i + 2], rgba[i + 3]};
}

}  // namespace hapsim::test
