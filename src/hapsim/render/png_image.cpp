#include "hapsim/render/png_image.h"

#include "hapsim/core/atomic_file.h"
#include "hapsim/core/error.h"

// The stb implementations live in this translation unit only.
#define STB_IMAGE_WRITE_IMPLEMENTATION
#define STB_IMAGE_IMPLEMENTATION
#define STBI_ONLY_PNG
#if defined(__GNUC__)
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wold-style-cast"
#pragma GCC diagnostic ignored "-Wcast-align"
#pragma GCC diagnostic ignored "-Wdouble-promotion"
#pragma GCC diagnostic ignored "-Wshadow"
#pragma GCC diagnostic ignored "-Wsign-compare"
#pragma GCC diagnostic ignored "-Wunused-function"
#pragma GCC diagnostic ignored "-Wmissing-field-initializers"
#pragma GCC diagnostic ignored "-Wpedantic"
#endif
#include <stb_image.h>
#include <stb_image_write.h>
#if defined(__GNUC__)
#pragma GCC diagnostic pop
#endif

#include <cstring>
#include <filesystem>
#include <memory>
#include <string>

namespace hapsim {

void write_png(const std::string& path, int width, int height, std::span<const std::uint8_t> rgba) {
  if (width <= 0 || height <= 0) {
    throw Error(
        path, "cannot write a PNG of size " + std::to_string(width) + "x" + std::to_string(height));
  }
  const std::size_t expected =
      static_cast<std::size_t>(width) * static_cast<std::size_t>(height) * 4;
  if (rgba.size() != expected) {
    throw Error(path, "expected " + std::to_string(expected) + " bytes of RGBA for " +
                          std::to_string(width) + "x" + std::to_string(height) + ", got " +
                          std::to_string(rgba.size()));
  }
  // Encoded in memory, then written atomically: stbi_write_png's own file writes are not checked
  // (a full disk gave a success and a 0-byte file), and a failed write keeps the old picture.
  std::string png;
  const auto append = [](void* context, void* data, int size) {
    static_cast<std::string*>(context)->append(static_cast<const char*>(data),
                                               static_cast<std::size_t>(size));
  };
  if (stbi_write_png_to_func(append, &png, width, height, 4, rgba.data(), width * 4) == 0) {
    throw Error(path, "cannot encode the PNG");
  }
  write_file_atomically(path, png);
}

RgbaImage read_png(const std::string& path) {
  if (!std::filesystem::exists(path)) {
    throw Error(path, "no such file");
  }
  int width = 0;
  int height = 0;
  int channels_in_file = 0;
  const std::unique_ptr<stbi_uc, void (*)(void*)> pixels(
      stbi_load(path.c_str(), &width, &height, &channels_in_file, 4), stbi_image_free);
  if (pixels == nullptr) {
    throw Error(path, std::string("cannot read as PNG: ") + stbi_failure_reason());
  }
  RgbaImage image;
  image.width = width;
  image.height = height;
  image.rgba.resize(static_cast<std::size_t>(width) * static_cast<std::size_t>(height) * 4);
  std::memcpy(image.rgba.data(), pixels.get(), image.rgba.size());
  return image;
}

}  // namespace hapsim
