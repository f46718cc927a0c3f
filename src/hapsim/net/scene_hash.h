// The 64-bit scene hash every sample carries (issue 12: samples "from another scene" are
// dropped): FNV-1a of the world's content hash (World::content_hash(), as recordings carry it),
// so both hosts derive it from the scene they loaded.
#pragma once

#include <cstdint>
#include <string_view>

namespace hapsim::net {

[[nodiscard]] constexpr std::uint64_t scene_hash(std::string_view content_hash) noexcept {
  std::uint64_t h = 1469598103934665603ULL;
  for (const char c : content_hash) {
    h ^= static_cast<unsigned char>(c);
    h *= 1099511628211ULL;
  }
  return h;
}

}  // namespace hapsim::net
