// Stage 2: which penalty segments each tool presses, how deep, and from which side.
#include "hapsim/world/world_model.h"
#include "hapsim/world/world_stages.h"
#include "hapsim/world/world_state.h"

#include <algorithm>
#include <cmath>

namespace hapsim::stage {

namespace {

void end_contact(WorldState& state, PenaltySide& side) noexcept {
  if (side.in_contact && side.crossed) {
    ++state.pop_throughs;  // left through the far side
  }
  side.in_contact = false;
  side.crossed = false;
}

}  // namespace

// haptic path
void detect_contacts(const WorldModel& model, WorldState& state) noexcept {
  if (!state.input_usable) {
    return;
  }
  const WorldDescription& d = model.description();
  const std::vector<SegmentModel>& segs = model.segments();
  for (std::size_t t = 0; t < state.tools.size(); ++t) {
    ToolRuntime& tool = state.tools[t];
    tool.penalty_count = 0;
    const double radius = d.tools[t].radius_m;
    const Vec3& p_world = tool.p_world;
    for (std::size_t i = 0; i < segs.size(); ++i) {
      const SegmentModel& seg = segs[i];
      if (seg.response != ContactResponse::kPenalty) {
        continue;
      }
      const ContactMaterial& material = state.materials[seg.material];
      const Vec3 p_body = seg.X_body_world * p_world;
      const double reach = radius + std::max(material.max_penetration_m, 0.0);
      PenaltySide& side = tool.penalty_side[i];
      // Cheap cull: outside the rest bounds grown by the reach nothing can touch.
      if ((p_body -
           p_body.cwiseMax(seg.rest_bounds_body.min()).cwiseMin(seg.rest_bounds_body.max()))
              .squaredNorm() > reach * reach) {
        end_contact(state, side);
        continue;
      }
      SurfacePoint sp;
      std::uint8_t& near = tool.near_last_step[i];
      if (!seg.rest_query->contact_within(p_body, reach, &sp, &tool.hints[i])) {
        // Either clear of the surface or deeper inside than the reach (saturated spring). Deeper
        // is only possible inside the bounds, and only for a tool that was near or inside last
        // step or has moved more than a reach since (a first cycle, a jump).
        if (!seg.rest_bounds_body.contains(p_body) || (near == 0 && tool.moved_m < reach)) {
          near = 0;
          end_contact(state, side);
          continue;
        }
        sp = seg.rest_query->closest_point(p_body, &tool.hints[i]);
        if (!(sp.signed_distance < 0.0)) {
          near = 0;
          end_contact(state, side);
          continue;
        }
      }
      near = 1;
      double depth = radius - sp.signed_distance;
      if (!(depth > 0.0) || !std::isfinite(depth)) {
        end_contact(state, side);
        continue;
      }
      Vec3 n_world = seg.X_world_body.linear() * sp.normal;
      Vec3 point_world = seg.X_world_body * sp.point;
      // Past the middle (or back): the nearest surface faces away from the entry side's normal.
      side.crossed = side.in_contact && n_world.dot(side.n_world) < 0.0;
      if (!side.crossed) {
        side.n_world = n_world;  // on the entry side: follow the surface
        side.point_world = point_world;
      } else {
        // Past the middle: push back out of the entry side, never further in.
        depth = radius - (p_world - side.point_world).dot(side.n_world);
        n_world = side.n_world;
        point_world = p_world - (radius - depth) * n_world;
      }
      side.in_contact = true;
      tool.penalty[tool.penalty_count++] =
          PenaltyCandidate{static_cast<std::uint32_t>(i), depth, n_world, point_world};
    }
  }
}

}  // namespace hapsim::stage
