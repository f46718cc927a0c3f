#include "hapsim/render/hand_figure.h"

#include <algorithm>
#include <array>

namespace hapsim {

void add_hand_figure(const HandModel& hand, const GloveReading& reading, const Vec3f& colour,
                     std::vector<RenderCapsule>& capsules) {
  const Iso3 X_world_hand =
      reading.X_world_hand.matrix().allFinite() ? reading.X_world_hand : Iso3::Identity();
  const HandGeometry& g = hand.geometry();
  // Phalanges thicker towards the palm, as a finger is.
  constexpr std::array<double, 3> kTaper{1.2, 1.08, 1.0};
  std::array<Iso3, 4> frames;
  for (int f = 0; f < kHandFingers; ++f) {
    const FingerGeometry& fg = g.fingers[static_cast<std::size_t>(f)];
    const double r = std::max(fg.tip_radius_m, 0.004);
    const Iso3 tip = hand.finger_frames_world(f, reading, frames);
    // frames: abduction and MCP flexion share the MCP; then the PIP, the DIP and the tip.
    const std::array<Vec3, 4> joints{frames[1].translation(), frames[2].translation(),
                                     frames[3].translation(), tip.translation()};
    for (std::size_t k = 0; k < 3; ++k) {
      capsules.push_back({joints[k], joints[k + 1], kTaper[k] * r, colour});
    }
  }
  // The palm: a slab of overlapping rods from the heel of the hand (narrower than the knuckles)
  // to points along the knuckle line through the four finger MCPs (each MCP one of them), and
  // that line itself.
  const auto at = [&](const Vec3& p_hand) { return Vec3(X_world_hand * p_hand); };
  const double palm_r = 1.3 * g.fingers[2].tip_radius_m;
  constexpr int kBetween = 2;  // rods between neighbouring MCPs
  for (int f = 1; f < kHandFingers; ++f) {
    const Vec3& a = g.fingers[static_cast<std::size_t>(f)].mcp_hand;
    const Vec3& b = g.fingers[static_cast<std::size_t>(std::min(f + 1, kHandFingers - 1))].mcp_hand;
    for (int k = 0; k <= (f + 1 < kHandFingers ? kBetween : 0); ++k) {
      const double u = static_cast<double>(k) / (kBetween + 1);
      const Vec3 knuckle = (1.0 - u) * a + u * b;
      const Vec3 heel(0.12 * knuckle.x(), 0.6 * knuckle.y(), knuckle.z());
      capsules.push_back({at(heel), at(knuckle), palm_r, colour});
    }
  }
  capsules.push_back(
      {at(g.fingers[1].mcp_hand), at(g.fingers[kHandFingers - 1].mcp_hand), palm_r, colour});
  // The thumb's metacarpal, from the heel on the thumb's side to its MCP.
  const FingerGeometry& thumb = g.fingers[0];
  const Vec3 thumb_base(0.2 * thumb.mcp_hand.x(), 0.45 * thumb.mcp_hand.y(),
                        0.5 * thumb.mcp_hand.z());
  capsules.push_back({at(thumb_base), at(thumb.mcp_hand), 1.4 * thumb.tip_radius_m, colour});
  // The wrist: a short rod back from the heel.
  capsules.push_back({at(Vec3(0.01, 0.0, 0.0)), at(Vec3(-0.03, 0.0, 0.0)), 1.8 * palm_r, colour});
}

}  // namespace hapsim
