// OffscreenContext: EGL surfaceless context creation and readback (clear colour exact, rows top
// first).
#include "hapsim/render/offscreen_context.h"

#include "render/gl_test_context.h"

#define GL_GLEXT_PROTOTYPES 1
#include <GL/glcorearb.h>

#include <gtest/gtest.h>

namespace hapsim {
namespace {

using test::pixel_at;

class OffscreenContextTest : public ::testing::TestWithParam<int> {};

TEST_P(OffscreenContextTest, ClearColourReadsBackExactlyTopRowFirst) {
  const int samples = GetParam();
  auto maybe = test::make_test_context(320, 240, samples);
  if (!maybe.context) {
    GTEST_SKIP() << "no offscreen GL context: " << maybe.why_not;
  }
  OffscreenContext& ctx = *maybe.context;
  EXPECT_EQ(ctx.width(), 320);
  EXPECT_EQ(ctx.height(), 240);
  EXPECT_GE(ctx.samples(), 1);
  EXPECT_FALSE(ctx.renderer_name().empty());

  // Whole frame one colour, then the top 40 GL rows (= the first 40 image rows) another.
  glClearColor(0.2f, 0.4f, 0.6f, 1.0f);
  glClear(GL_COLOR_BUFFER_BIT);
  glEnable(GL_SCISSOR_TEST);
  glScissor(0, 240 - 40, 320, 40);
  glClearColor(1.0f, 0.0f, 0.0f, 1.0f);
  glClear(GL_COLOR_BUFFER_BIT);
  glDisable(GL_SCISSOR_TEST);

  const std::vector<std::uint8_t> rgba = ctx.read_rgba();
  ASSERT_EQ(rgba.size(), 320u * 240u * 4u);
  for (const auto& [x, y] : {std::pair{0, 0}, std::pair{319, 39}}) {
    const auto p = pixel_at(rgba, 320, x, y);
    EXPECT_EQ(p.r, 255);
    EXPECT_EQ(p.g, 0);
    EXPECT_EQ(p.b, 0);
  }
  for (const auto& [x, y] : {std::pair{0, 40}, std::pair{160, 120}, std::pair{319, 239}}) {
    const auto p = pixel_at(rgba, 320, x, y);
    EXPECT_EQ(p.r, 51);  // 0.2 · 255
    EXPECT_EQ(p.g, 102);
    EXPECT_EQ(p.b, 153);
    EXPECT_EQ(p.a, 255);
  }
}

INSTANTIATE_TEST_SUITE_P(Samples, OffscreenContextTest, ::testing::Values(1, 4));

TEST(OffscreenContext, TwoContextsCanLiveAtOnce) {
  auto a = test::make_test_context(64, 32);
  if (!a.context) {
    GTEST_SKIP() << "no offscreen GL context: " << a.why_not;
  }
  auto b = test::make_test_context(16, 16);
  ASSERT_TRUE(b.context) << b.why_not;
  b.context.reset();  // must not end `a` (the EGL display is shared)
  a.context->make_current();
  glClearColor(0.0f, 1.0f, 0.0f, 1.0f);
  glClear(GL_COLOR_BUFFER_BIT);
  const auto rgba = a.context->read_rgba();
  EXPECT_EQ(pixel_at(rgba, 64, 10, 10).g, 255);
}

TEST(OffscreenContext, RejectsNonPositiveSize) {
  EXPECT_THROW(OffscreenContext(0, 10), Error);
}

}  // namespace
}  // namespace hapsim
