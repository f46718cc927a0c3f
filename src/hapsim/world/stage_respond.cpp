// Stage 3: forces. Proxy segments through each tool's god-object, penalty segments as springs on
// the contacts the detection stage found; every contact reported and handed to deformation.
#include "hapsim/force/contact_friction.h"
#include "hapsim/force/penalty_force.h"
#include "hapsim/world/world_model.h"
#include "hapsim/world/world_stages.h"
#include "hapsim/world/world_state.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <span>

namespace hapsim::stage {

namespace {

// Where one of a tool's sheet pushes went this step (to rescale it once the tool's force is
// known). A tool presses a handful of sheet segments at most.
struct SheetPushSlot {
  SegmentState* sheet = nullptr;
  std::size_t index = 0;
};
constexpr std::size_t kMaxRescaledSheetPushes = 8;

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
void add_sheet_push(SegmentState& sheet, const Iso3& X_sheet_world, const Vec3& p_world,
                    const Vec3& force_on_presser_world_n) noexcept {
  if (sheet.sheet_push_count >= sheet.sheet_pushes.size()) {
    return;
  }
  // The sheet is pushed down (along its −z) by what pushes the presser up.
  const double push_n = (X_sheet_world.linear() * force_on_presser_world_n).z();
  sheet.sheet_pushes[sheet.sheet_push_count++] =
      SheetContact{X_sheet_world * p_world, std::max(push_n, 0.0)};
}

namespace {

// SPEC §8: a sheet pressed by a tool whose device rendered `rendered_push_n` (NaN: not known)
// gives way to that push, not to the step's `step_push_n`: its pushes scaled by their ratio.
// haptic path
void drive_sheets_with_rendered_push(double rendered_push_n, double step_push_n,
                                     std::span<const SheetPushSlot> pushes) noexcept {
  if (pushes.empty() || !std::isfinite(rendered_push_n) || !(step_push_n > 0.0)) {
    return;
  }
  const double scale = std::max(rendered_push_n, 0.0) / step_push_n;
  for (const SheetPushSlot& slot : pushes) {
    slot.sheet->sheet_pushes[slot.index].force_n *= scale;
  }
}

// A proxy never passes through a closed surface, but a defect (a query's wrong side, a
// friction step off a curved surface) could let it go while the device is still inside the body:
// the hand would feel the bone vanish with nothing said. Such a loss is counted as a
// pop-through. One closest-point query, only on the cycle a contact ends. haptic path
void count_proxy_loss(WorldState& state, ToolRuntime& tool) noexcept {
  const int last = tool.proxy_surface_last_step;
  tool.proxy_surface_last_step =
      tool.proxy.in_contact() ? tool.proxy.contacts().front().surface : -1;
  if (last < 0 || tool.proxy.in_contact() ||
      static_cast<std::size_t>(last) >= tool.surfaces.size()) {
    return;
  }
  const ProxySurface& s = tool.surfaces[static_cast<std::size_t>(last)];
  if (s.query == nullptr || s.two_sided) {
    return;  // an open sheet has no inside
  }
  // A free proxy reaches the device within the cycle: the tool sphere overlapping the body
  // (beyond 0.1 mm, clear of rounding) with no proxy contact is a proxy that went astray.
  const SurfacePoint sp = s.query->closest_point(s.X_world_body.inverse() * tool.p_world);
  if (sp.signed_distance < tool.proxy.params().radius_m - 1e-4) {
    ++state.pop_throughs;
  }
}

}  // namespace

// haptic path
void respond(const WorldModel& model, WorldState& state, double /*dt_s*/) noexcept {
  const WorldDescription& d = model.description();
  const std::vector<SegmentModel>& segs = model.segments();
  for (std::size_t t = 0; t < state.tools.size(); ++t) {
    ToolRuntime& tool = state.tools[t];
    if (!tool.input_usable) {
      continue;
    }
    ToolState& out = state.tool_states[t];
    const double radius = d.tools[t].radius_m;
    const ToolIndex tool_index{t};
    out.p_world = tool.p_world;
    out.contact_count = 0;

    // Proxy segments: the god-object's proxy never enters them; the spring pulls the tool to it.
    tool.proxy.update(tool.p_world, tool.surfaces);
    count_proxy_loss(state, tool);
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
          state, WorldContact{tool_index, BodyIndex{seg.body}, seg.index_in_body, c.point_world,
                              c.normal_world, depth, first ? proxy_force_world.norm() : 0.0, true});
      first = false;
      ++out.contact_count;
      if (depth > 0.0) {
        add_pending(state.segments[flat],
                    DeflectionContact{state.X_body_world(seg) * c.point_world, depth, radius, 0});
      }
    }

    // Penalty segments, at the tool's own position: F = k·x along the entry side's normal, plus
    // friction where the material has it; the body gets the opposite.
    std::array<SheetPushSlot, kMaxRescaledSheetPushes> sheet_pushes{};
    std::size_t sheet_push_count = 0;
    std::size_t next = 0;  // penalty candidates come in segment order
    for (std::size_t i = 0; i < segs.size(); ++i) {
      while (next < tool.penalty_count && tool.penalty[next].segment.index() < i) {
        ++next;
      }
      if (next < tool.penalty_count && tool.penalty[next].segment.index() == i) {
        continue;
      }
      tool.stick_body[i].active = false;  // not pressing this segment: nothing sticks
    }
    for (std::size_t k = 0; k < tool.penalty_count; ++k) {
      const PenaltyCandidate& c = tool.penalty[k];
      const std::size_t flat = c.segment.index();
      const SegmentModel& seg = segs[flat];
      const ContactMaterial& material = state.materials[seg.material];
      BodyState& body = state.bodies[seg.body];
      const BodyModel& body_model = model.bodies()[seg.body];
      const Vec3 v_rel =
          seg.dynamic ? Vec3(tool.v_world - body.velocity_at(c.point_world, body_model.com_body))
                      : tool.v_world;
      const Vec3 f_normal = penalty_force(material, c.depth_m, c.n_world, -v_rel.dot(c.n_world));
      // Friction follows the tool's own contact point (its sphere's surface towards the segment)
      // against the material point of the segment where it stuck: what slips is the one over
      // the other (the closest point on the segment slides over it as the geometry changes).
      StickPoint stick{tool.stick_body[flat].active, body.X_world_body * tool.stick_body[flat].p};
      const Vec3 f_friction = contact_friction_force(material, f_normal.norm(), c.n_world, v_rel,
                                                     tool.p_world - radius * c.n_world, stick);
      const Vec3 f = f_normal + f_friction;
      tool.stick_body[flat] = {stick.active, body.X_body_world * stick.p};
      if (seg.dynamic) {
        body.force_world_n -= f;
        body.torque_world_nm -= (c.point_world - body.com_world(body_model.com_body)).cross(f);
        // The tool is where the device puts it: to the body, a spring to a fixed point.
        linearise_penalty(body, body_model, c.point_world, c.n_world, material, c.depth_m,
                          f_normal.norm(), tool.v_world);
        linearise_friction(body, body_model, c.point_world, c.n_world, material, f_normal.norm(),
                           f_friction, tool.v_world);
      }
      if (seg.sheet) {
        SegmentState& sheet = state.segments[flat];
        if (sheet_push_count < sheet_pushes.size() &&
            sheet.sheet_push_count < sheet.sheet_pushes.size()) {
          sheet_pushes[sheet_push_count++] = {&sheet, sheet.sheet_push_count};
        }
        add_sheet_push(sheet, body.X_body_world, c.point_world, f);
      }
      total += f;
      add_contact(state, WorldContact{tool_index, BodyIndex{seg.body}, seg.index_in_body,
                                      c.point_world, c.n_world, c.depth_m, f.norm(), false});
      ++out.contact_count;
      // The surface deflects to reach the tool: eq. 1 about the rest point, to the rest depth.
      SegmentState& seg_state = state.segments[flat];
      add_pending(seg_state, DeflectionContact{c.rest_point_body, c.rest_depth_m, radius, 0});
      if (seg_state.deflection) {
        tool.own_dent[flat] = OwnDent{c.rest_point_body, c.rest_depth_m, radius, state.step_index};
      }
    }
    out.force_world_n = total;
    drive_sheets_with_rendered_push(state.rendered_push_n[t], total.norm(),
                                    {sheet_pushes.data(), sheet_push_count});
  }
}

}  // namespace hapsim::stage
