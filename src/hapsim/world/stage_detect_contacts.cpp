// Stage 2: which penalty segments each tool presses, how deep, and from which side.
#include "hapsim/deform/vertex_deflection.h"
#include "hapsim/world/world_model.h"
#include "hapsim/world/world_stages.h"
#include "hapsim/world/world_state.h"

#include <algorithm>
#include <cmath>

namespace hapsim::stage {

namespace {

// The surface's current dent at a rest-surface point `p_body` on triangle `tri`: the vertex
// deflections interpolated over the triangle (linear, as the surface is drawn).
double surface_dent_m(const SegmentModel& seg, const VertexDeflection& deflection,
                      const Vec3& p_body, std::uint32_t tri) noexcept {
  const TriangleMesh& rest = seg.description->mesh;
  if (tri >= rest.triangles.size()) {
    return 0.0;
  }
  const TriangleIndices& t = rest.triangles[tri];
  const Vec3& a = rest.vertices[t[0]];
  const Vec3 ab = rest.vertices[t[1]] - a;
  const Vec3 ac = rest.vertices[t[2]] - a;
  const Vec3 ap = p_body - a;
  const double d00 = ab.dot(ab);
  const double d01 = ab.dot(ac);
  const double d11 = ac.dot(ac);
  const double d20 = ap.dot(ab);
  const double d21 = ap.dot(ac);
  const double den = d00 * d11 - d01 * d01;
  if (!(den > 0.0)) {
    return 0.0;
  }
  const double v = std::clamp((d11 * d20 - d01 * d21) / den, 0.0, 1.0);
  const double w = std::clamp((d00 * d21 - d01 * d20) / den, 0.0, 1.0 - v);
  const double u = 1.0 - v - w;
  return std::max(0.0, u * deflection.deflection_m(t[0]) + v * deflection.deflection_m(t[1]) +
                           w * deflection.deflection_m(t[2]));
}

// The deepest of the other tools' last-step dents (eq. 1 each) at `p_body` on segment `flat`.
double others_dent_m(const WorldState& state, std::size_t tool, std::size_t flat,
                     const DeflectionParams& params, const Vec3& p_body) noexcept {
  double deepest = 0.0;
  for (std::size_t u = 0; u < state.tools.size(); ++u) {
    const OwnDent& dent = state.tools[u].own_dent[flat];
    if (u == tool || dent.step == 0 || dent.step + 1 != state.step_index) {
      continue;
    }
    const double x = std::min(dent.penetration_m, params.max_deflection_m);
    const double d0 = VertexDeflection::zero_deflection_distance_m(x, dent.contact_radius_m,
                                                                   params.elasticity_factor);
    deepest = std::max(
        deepest, VertexDeflection::deflection_profile_m((p_body - dent.p_body).norm(), x, d0));
  }
  return deepest;
}

// How deep the surface under a tool is dented by others this step (see ToolRuntime::felt_dent_m).
double felt_dent_m(const SegmentModel& seg, const SegmentState& seg_state,
                   const DeflectionParams& params, const WorldState& state, std::size_t tool,
                   std::size_t flat, bool was_pressing, double previous_m, const Vec3& p_body,
                   std::uint32_t tri, double dt_s) noexcept {
  // The other tools' presses (eq. 1, exact whatever the mesh's resolution), and when the tool
  // starts pressing, the surface as it is there (a dent still recovering).
  const double others = others_dent_m(state, tool, flat, params, p_body);
  if (!was_pressing) {
    return std::max(others, surface_dent_m(seg, *seg_state.deflection, p_body, tri));
  }
  if (previous_m <= others) {
    return others;
  }
  const double tau = params.recovery_time_constant_s;
  const double decay = tau > 0.0 ? std::exp(-dt_s / tau) : 0.0;
  return others + VertexDeflection::recover_gap_m(params, decay, previous_m - others, dt_s);
}

void end_contact(WorldState& state, PenaltySide& side) noexcept {
  if (side.in_contact && side.crossed) {
    ++state.pop_throughs;  // left through the far side
  }
  side.in_contact = false;
  side.crossed = false;
}

}  // namespace

// haptic path
void detect_contacts(const WorldModel& model, WorldState& state, double dt_s) noexcept {
  const WorldDescription& d = model.description();
  const std::vector<SegmentModel>& segs = model.segments();
  for (std::size_t t = 0; t < state.tools.size(); ++t) {
    ToolRuntime& tool = state.tools[t];
    tool.penalty_count = 0;
    if (!tool.input_usable) {
      continue;
    }
    const double radius = d.tools[t].radius_m;
    const Vec3& p_world = tool.p_world;
    for (std::size_t i = 0; i < segs.size(); ++i) {
      const SegmentModel& seg = segs[i];
      if (seg.response != ContactResponse::kPenalty || seg.fem) {
        continue;  // FEM bodies: their local contact models (stage_fem_contacts.cpp)
      }
      const ContactMaterial& material = state.materials[seg.material];
      const Vec3 p_body = state.X_body_world(seg) * p_world;
      const ProximityQuery& query = state.contact_query(seg, i);
      const bool was_pressing = tool.pressing[i] != 0;
      tool.pressing[i] = 0;  // set again below when the tool presses the segment this step
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
      if (!query.contact_within(p_body, reach, &sp, &tool.hints[i])) {
        // Either clear of the surface or deeper inside than the reach (saturated spring). Deeper
        // is only possible inside the bounds, and only for a tool that was near or inside last
        // step or has moved more than a reach since (a first cycle, a jump).
        if (!seg.rest_bounds_body.contains(p_body) || (near == 0 && tool.moved_m < reach)) {
          near = 0;
          end_contact(state, side);
          continue;
        }
        sp = query.closest_point(p_body, &tool.hints[i]);
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
      const Iso3& X_world_body = state.X_world_body(seg);
      Vec3 n_world = X_world_body.linear() * sp.normal;
      Vec3 point_world = X_world_body * sp.point;
      Vec3 rest_point_body = sp.point;
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
        rest_point_body = state.X_body_world(seg) * point_world;
      }
      const double rest_depth = depth;
      const SegmentState& seg_state = state.segments[i];
      if (seg_state.deflection && !side.crossed) {
        // The surface this tool feels is lowered by the dent others left under it.
        const double dent =
            felt_dent_m(seg, seg_state, d.materials[seg.material].deflection, state, t, i,
                        was_pressing, tool.felt_dent_m[i], sp.point, sp.triangle, dt_s);
        tool.felt_dent_m[i] = dent;
        depth -= dent;
        if (!(depth > 0.0)) {
          // Inside the rest surface but clear of the dent: nothing touches.
          end_contact(state, side);
          continue;
        }
        point_world -= dent * n_world;  // on the dented surface
        tool.pressing[i] = 1;
      }
      side.in_contact = true;
      tool.penalty[tool.penalty_count++] = PenaltyCandidate{
          FlatSegment{i}, depth, rest_depth, n_world, point_world, rest_point_body};
    }
  }
}

}  // namespace hapsim::stage
