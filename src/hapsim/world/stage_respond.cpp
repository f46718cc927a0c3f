// Stage 3: forces. Proxy segments through each tool's god-object, penalty segments as springs on
// the contacts the detection stage found; every contact reported and handed to deformation.
#include "hapsim/force/penalty_force.h"
#include "hapsim/world/world_model.h"
#include "hapsim/world/world_stages.h"
#include "hapsim/world/world_state.h"

#include <algorithm>

namespace hapsim::stage {

namespace {

void add_contact(WorldState& state, const WorldContact& contact) noexcept {
  if (state.contact_count < state.contacts.size()) {
    state.contacts[state.contact_count++] = contact;
  } else {
    ++state.dropped_contacts;
  }
}

void add_pending(SegmentState& seg, const DeflectionContact& contact) noexcept {
  if (seg.deflection && seg.pending_count < seg.pending.size()) {
    seg.pending[seg.pending_count++] = contact;
  }
}

}  // namespace

// haptic path
void respond(const WorldModel& model, WorldState& state, double dt_s) noexcept {
  if (state.rig) {
    // The rig's gripper pads against the ball: grasp, hold or release.
    RigState& rig = *state.rig;
    rig.result.gripper =
        rig.gripper.step(rig.result.slave_tool, rig.slave->gripper_width_m(), rig.ball, dt_s);
  }
  if (!state.input_usable) {
    return;
  }
  const WorldDescription& d = model.description();
  const std::vector<SegmentModel>& segs = model.segments();
  for (std::size_t t = 0; t < state.tools.size(); ++t) {
    ToolRuntime& tool = state.tools[t];
    ToolState& out = state.tool_states[t];
    const double radius = d.tools[t].radius_m;
    const auto tool_index = static_cast<std::int32_t>(t);
    out.p_world = tool.p_world;
    out.contact_count = 0;

    // Proxy segments: the god-object's proxy never enters them; the spring pulls the tool to it.
    tool.proxy.update(tool.p_world, tool.surfaces);
    const Vec3 proxy_force_world =
        proxy_force(tool.proxy, tool.surfaces, tool.p_world, tool.v_world);
    Vec3 total = proxy_force_world;
    out.proxy_world = tool.proxy.proxy_world();
    bool first = true;
    for (const ProxyContact& c : tool.proxy.contacts()) {
      const std::size_t flat = tool.surface_segment[static_cast<std::size_t>(c.surface)];
      const SegmentModel& seg = segs[flat];
      const double depth =
          std::max(0.0, (tool.proxy.proxy_world() - tool.p_world).dot(c.normal_world));
      // proxy_force() renders the first contact's material along the spring; report it there.
      add_contact(
          state, WorldContact{tool_index, static_cast<std::int32_t>(seg.body),
                              static_cast<std::int32_t>(seg.index_in_body), c.point_world,
                              c.normal_world, depth, first ? proxy_force_world.norm() : 0.0, true});
      first = false;
      ++out.contact_count;
      if (depth > 0.0) {
        add_pending(state.segments[flat],
                    DeflectionContact{seg.X_body_world * c.point_world, depth, radius, 0});
      }
    }

    // Penalty segments, at the tool's own position: F = k·x along the entry side's normal.
    for (std::size_t k = 0; k < tool.penalty_count; ++k) {
      const PenaltyCandidate& c = tool.penalty[k];
      const SegmentModel& seg = segs[c.segment];
      const ContactMaterial& material = state.materials[seg.material];
      const Vec3 f = penalty_force(material, c.depth_m, c.n_world, -tool.v_world.dot(c.n_world));
      total += f;
      add_contact(state, WorldContact{tool_index, static_cast<std::int32_t>(seg.body),
                                      static_cast<std::int32_t>(seg.index_in_body), c.point_world,
                                      c.n_world, c.depth_m, f.norm(), false});
      ++out.contact_count;
      // The surface deflects to reach the tool: eq. 1 about the rest point, to the rest depth.
      SegmentState& seg_state = state.segments[c.segment];
      add_pending(seg_state, DeflectionContact{c.rest_point_body, c.rest_depth_m, radius, 0});
      if (seg_state.deflection) {
        tool.own_dent[c.segment] =
            OwnDent{c.rest_point_body, c.rest_depth_m, radius, state.step_index};
      }
    }
    out.force_world_n = total;
  }
}

}  // namespace hapsim::stage
