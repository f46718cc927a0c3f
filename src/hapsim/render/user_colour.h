// The colour each user's tools are drawn in when free (several users in one world: the scene's
// device hosts, in order). Chosen apart from the force heat's red, the proxies' blue and the
// hand's lilac; a fifth user (there are at most four) would wrap round.
#pragma once

#include "hapsim/render/render_scene.h"

#include <array>
#include <cstddef>

namespace hapsim {

/// Device `device`'s colour (0: the first user, green).
[[nodiscard]] inline Vec3f user_colour(int device) {
  // Each blends into the force heat's red through a colour still its own (amber through orange,
  // magenta through crimson); a blue one passes through grey, so cyan comes last.
  static const std::array<Vec3f, 4> kColours{Vec3f(0.2f, 0.8f, 0.25f),    // green
                                             Vec3f(1.0f, 0.75f, 0.1f),    // amber
                                             Vec3f(0.85f, 0.3f, 0.85f),   // magenta
                                             Vec3f(0.1f, 0.75f, 0.85f)};  // cyan
  return kColours[static_cast<std::size_t>(device < 0 ? 0 : device) % kColours.size()];
}

}  // namespace hapsim
