// Stage 3b: FEM bodies, from the local contact models the FEM side handed over (fem_coupling.h).
// Each cycle the model is evaluated at the tool's fresh position, as a device host renders a
// served model: the push along the model's normal from f0 at x0 and the series stiffness
// (contact spring and tissue), plus the contact's damping (never below the passivity floor
// factor·k·dt, nor the floor the FEM side asks for: fem_contact_damping_n_s_per_m), held to the
// contact's force cap, push-only, zero beyond the validity radius. The force rendered is the FEM's
// load at its next update (SPEC §8: the tissue yields to what the hand felt); with
// World::set_rendered_push (a served world) the device's own push replaces it.
#include "hapsim/world/fem_coupling.h"
#include "hapsim/world/world_model.h"
#include "hapsim/world/world_stages.h"
#include "hapsim/world/world_state.h"
#include "hapsim/world/world_step.h"

#include <algorithm>
#include <cmath>

namespace hapsim::stage {

// haptic path
void fem_contacts(const WorldModel& model, WorldState& state, double dt_s) noexcept {
  const std::vector<std::size_t>& fem_bodies = model.fem_bodies();
  if (fem_bodies.empty()) {
    return;
  }
  const WorldDescription& d = model.description();
  for (std::size_t t = 0; t < state.tools.size() && t < kMaxTools; ++t) {
    ToolRuntime& tool = state.tools[t];
    ToolState& out = state.tool_states[t];
    const double radius = d.tools[t].radius_m;
    for (std::size_t b = 0; b < fem_bodies.size(); ++b) {
      FemToolContact& fc = state.fem_contacts[t * kMaxFemBodies + b];
      fc.push_world_n.setZero();
      const LocalContactModel& m = fc.model;
      if (!state.input_usable || !m.valid) {
        continue;
      }
      if ((tool.p_world - m.x0_world_m).norm() > m.validity_radius_m) {
        continue;  // the linearisation is not trusted this far out: the next update will be
      }
      const Vec3& n = m.normal_world;
      const double k_n = n.dot(m.stiffness_n_per_m * n);
      const double spring_n = n.dot(local_model_force(m, tool.p_world, m.v0_world_m_per_s));
      if (!(spring_n > 0.0) || !std::isfinite(spring_n)) {
        continue;  // clear of the surface: nothing touches, nothing damps
      }
      const SegmentModel& seg = model.segments()[model.flat_segment(fem_bodies[b], 0)];
      const ContactMaterial& material = state.materials[seg.material];
      const double damping =
          fem_contact_damping_n_s_per_m(model, state.material_contact[seg.material], m, dt_s);
      const double push_n =
          std::clamp(spring_n - damping * tool.v_world.dot(n), 0.0,
                     std::min(m.max_normal_force_n, std::max(material.max_force_n, 0.0)));
      const Vec3 f = push_n * n;
      fc.push_world_n = f;
      out.force_world_n += f;
      const double depth_m = k_n > 0.0 ? spring_n / k_n : 0.0;
      if (state.contact_count < state.contacts.size()) {
        state.contacts[state.contact_count++] =
            WorldContact{static_cast<std::int32_t>(t),
                         static_cast<std::int32_t>(fem_bodies[b]),
                         0,
                         tool.p_world - radius * n,
                         n,
                         depth_m,
                         push_n,
                         false};
      } else {
        ++state.dropped_contacts;
      }
      ++out.contact_count;
    }
    // A served world: the tissue takes what the device rendered, shared over the FEM contacts in
    // proportion to what the step gave each.
    const double rendered = state.rendered_push_n[t];
    if (std::isfinite(rendered)) {
      double step_total = 0.0;
      for (std::size_t b = 0; b < fem_bodies.size(); ++b) {
        step_total += state.fem_contacts[t * kMaxFemBodies + b].push_world_n.norm();
      }
      if (step_total > 0.0) {
        const double scale = std::max(rendered, 0.0) / step_total;
        for (std::size_t b = 0; b < fem_bodies.size(); ++b) {
          state.fem_contacts[t * kMaxFemBodies + b].push_world_n *= scale;
        }
      }
    }
  }
}

}  // namespace hapsim::stage
