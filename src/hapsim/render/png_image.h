// PNG files for screenshots and reference images (stb_image / stb_image_write). Pixels are RGBA8,
// top row first, as OffscreenContext::read_rgba() returns them.
#pragma once

#include <cstdint>
#include <span>
#include <string>
#include <vector>

namespace hapsim {

struct RgbaImage {
  int width = 0;
  int height = 0;
  /// width·height·4 bytes, top row first.
  std::vector<std::uint8_t> rgba;
};

/// Writes an RGBA8 PNG. Throws hapsim::Error naming `path` if the size does not match or the
/// file cannot be written.
void write_png(const std::string& path, int width, int height, std::span<const std::uint8_t> rgba);

/// Reads any PNG as RGBA8 (grey/RGB/palette expanded, alpha 255 where absent). Throws
/// hapsim::Error naming `path` if it is missing or not a readable image.
RgbaImage read_png(const std::string& path);

}  // namespace hapsim
