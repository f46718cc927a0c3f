// PNG write/read through stb: exact round trip, errors name the file.
#include "hapsim/render/png_image.h"

#include "hapsim/core/error.h"

#include <gtest/gtest.h>

#include <filesystem>

namespace hapsim {
namespace {

std::filesystem::path temp_path(const std::string& name) {
  return std::filesystem::temp_directory_path() /
         (std::string("hapsim_png_") +
          std::to_string(::testing::UnitTest::GetInstance()->random_seed()) + "_" + name);
}

TEST(PngImage, WriteThenReadRoundTripsExactly) {
  const int w = 37;  // odd width: no row padding assumptions
  const int h = 23;
  std::vector<std::uint8_t> rgba(static_cast<std::size_t>(w * h * 4));
  for (std::size_t i = 0; i < rgba.size(); ++i) {
    rgba[i] = static_cast<std::uint8_t>((i * 97 + i / 7) % 256);
  }
  const auto path = temp_path("roundtrip.png");
  write_png(path.string(), w, h, rgba);
  const RgbaImage back = read_png(path.string());
  std::filesystem::remove(path);
  EXPECT_EQ(back.width, w);
  EXPECT_EQ(back.height, h);
  EXPECT_EQ(back.rgba, rgba);
}

TEST(PngImage, ReadingAMissingFileNamesIt) {
  const std::string path = "/nonexistent/folder/reference.png";
  try {
    (void)read_png(path);
    FAIL() << "expected hapsim::Error";
  } catch (const Error& e) {
    EXPECT_EQ(e.where(), path);
    EXPECT_NE(std::string(e.what()).find("reference.png"), std::string::npos);
  }
}

TEST(PngImage, ReadingANonPngNamesIt) {
  const auto path = temp_path("not_a.png");
  {
    std::FILE* f = std::fopen(path.string().c_str(), "wb");
    ASSERT_NE(f, nullptr);
    std::fputs("this is not a png", f);
    std::fclose(f);
  }
  try {
    (void)read_png(path.string());
    FAIL() << "expected hapsim::Error";
  } catch (const Error& e) {
    EXPECT_EQ(e.where(), path.string());
  }
  std::filesystem::remove(path);
}

TEST(PngImage, WriteChecksSizeAndFolder) {
  const std::vector<std::uint8_t> rgba(4 * 4 * 4, 0);
  EXPECT_THROW(write_png("x.png", 5, 4, rgba), Error);
  try {
    write_png("/nonexistent/folder/out.png", 4, 4, rgba);
    FAIL() << "expected hapsim::Error";
  } catch (const Error& e) {
    EXPECT_EQ(e.where(), "/nonexistent/folder/out.png");
  }
}

}  // namespace
}  // namespace hapsim
