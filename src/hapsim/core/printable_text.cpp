#include "hapsim/core/printable_text.h"

#include <array>
#include <cstdint>

namespace hapsim {
namespace {

void append_escaped(std::string& out, unsigned char byte) {
  constexpr std::array<char, 16> kHex = {'0', '1', '2', '3', '4', '5', '6', '7',
                                         '8', '9', 'a', 'b', 'c', 'd', 'e', 'f'};
  out += "\\x";
  out += kHex[byte >> 4U];
  out += kHex[byte & 0xfU];
}

// Length of the valid UTF-8 sequence starting at text[i] that encodes a printable code point
// (no C1 control, no overlong form, no surrogate), or 0.
std::size_t printable_utf8_length(std::string_view text, std::size_t i) {
  const auto b0 = static_cast<unsigned char>(text[i]);
  std::size_t length = 0;
  std::uint32_t code = 0;
  if (b0 >= 0xc2 && b0 <= 0xdf) {
    length = 2;
    code = b0 & 0x1fU;
  } else if (b0 >= 0xe0 && b0 <= 0xef) {
    length = 3;
    code = b0 & 0x0fU;
  } else if (b0 >= 0xf0 && b0 <= 0xf4) {
    length = 4;
    code = b0 & 0x07U;
  } else {
    return 0;
  }
  if (i + length > text.size()) {
    return 0;
  }
  for (std::size_t k = 1; k < length; ++k) {
    const auto b = static_cast<unsigned char>(text[i + k]);
    if ((b & 0xc0U) != 0x80U) {
      return 0;
    }
    code = (code << 6U) | (b & 0x3fU);
  }
  const bool overlong = (length == 3 && code < 0x800) || (length == 4 && code < 0x10000);
  const bool c1_control = code >= 0x80 && code <= 0x9f;
  const bool surrogate = code >= 0xd800 && code <= 0xdfff;
  if (overlong || c1_control || surrogate || code > 0x10ffff) {
    return 0;
  }
  return length;
}

}  // namespace

std::string printable_text(std::string_view text, std::size_t max_bytes) {
  const bool cut = text.size() > max_bytes;
  const std::string_view shown = cut ? text.substr(0, max_bytes) : text;
  std::string out;
  out.reserve(shown.size() + 8);
  for (std::size_t i = 0; i < shown.size();) {
    const auto byte = static_cast<unsigned char>(shown[i]);
    if (byte == '\\') {
      out += "\\\\";
      ++i;
    } else if (byte >= 0x20 && byte < 0x7f) {
      out += static_cast<char>(byte);
      ++i;
    } else if (const std::size_t n = byte >= 0x80 ? printable_utf8_length(shown, i) : 0; n > 0) {
      out.append(shown.substr(i, n));
      i += n;
    } else {
      append_escaped(out, byte);
      ++i;
    }
  }
  if (cut) {
    out += "...";
  }
  return out;
}

}  // namespace hapsim
