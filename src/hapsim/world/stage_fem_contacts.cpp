// Stage 3b: FEM bodies, from the local contact models the FEM side handed over (fem_coupling.h).
// Each cycle the model is evaluated at the tool's fresh position, as a device host renders a
// served model: the push along the model's normal from f0 at x0 and the series stiffness
// (contact spring and tissue), plus the contact's damping (never below the passivity floor
// factor·k·dt, nor the floor the FEM side asks for: fem_contact_damping_n_s_per_m), held to the
// contact's force cap, push-only, zero beyond the validity radius. The force rendered is the FEM's
// load at its next update (SPEC §8: the tissue yields to what the hand felt); with
// World::set_rendered_push (a served world) the device's own push replaces it.
//
// A newly adopted model is blended in over one FEM period: the difference between what the old
// model rendered at the tool and what the new one renders there decays linearly to zero, so the
// force between two updates is a ramp from one model to the next, not a step when the next
// arrives (a fingertip sliding at 500 mm/s moves 5 mm per update over tissue whose thickness
// changes under it: 9.5 N steps before). A device host blends served models the same way
// (device/local_model_renderer.h).
#include "hapsim/world/fem_coupling.h"
#include "hapsim/world/world_model.h"
#include "hapsim/world/world_stages.h"
#include "hapsim/world/world_state.h"
#include "hapsim/world/world_step.h"

#include <algorithm>
#include <cmath>

namespace hapsim::stage {
namespace {

// What one local model renders at the tool (world frame), push-only and capped; zero when it is
// invalid, trusted no further than its validity radius, or the tool is clear of its surface.
// `spring_n` gets the spring's push along the normal (no damping), 0 when nothing touches.
// haptic path
Vec3 model_push_n(const WorldModel& model, const WorldState& state, const LocalContactModel& m,
                  const ContactMaterial& material, std::size_t material_index,
                  const ToolRuntime& tool, double dt_s, double& spring_n) noexcept {
  spring_n = 0.0;
  if (!m.valid || (tool.p_world - m.x0_world_m).norm() > m.validity_radius_m) {
    return Vec3::Zero();  // beyond the radius the linearisation is not trusted: the next update is
  }
  const Vec3& n = m.normal_world;
  const double spring = n.dot(local_model_force(m, tool.p_world, m.v0_world_m_per_s));
  if (!(spring > 0.0) || !std::isfinite(spring)) {
    return Vec3::Zero();  // clear of the surface: nothing touches, nothing damps
  }
  spring_n = spring;
  const double damping =
      fem_contact_damping_n_s_per_m(model, state.material_contact[material_index], m, dt_s);
  const double push_n =
      std::clamp(spring - damping * tool.v_world.dot(n), 0.0,
                 std::min(m.max_normal_force_n, std::max(material.max_force_n, 0.0)));
  return push_n * n;
}

}  // namespace

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
      if (!tool.input_usable) {
        fc.adopted_this_step = false;
        fc.blend_offset_n.setZero();
        continue;
      }
      const SegmentModel& seg =
          model.segments()[model.flat_segment(BodyIndex{fem_bodies[b]}, LocalSegment{0}).index()];
      const ContactMaterial& material = state.materials[seg.material];
      // One FEM period, in steps: the blend ends as the next model arrives.
      const FemBodyDescription* fem = d.bodies[fem_bodies[b]].fem.get();
      const double blend_steps =
          fem != nullptr && dt_s > 0.0 ? std::max(1.0, std::round(fem->options.dt_s / dt_s)) : 1.0;
      const auto blend_left = [&]() {
        const double done = static_cast<double>(state.step_index - fc.blend_from_step);
        return std::clamp(1.0 - done / blend_steps, 0.0, 1.0);
      };
      double spring_n = 0.0;
      const LocalContactModel& m = fc.model;
      const Vec3 new_push =
          model_push_n(model, state, m, material, seg.material, tool, dt_s, spring_n);
      if (fc.adopted_this_step) {
        double unused = 0.0;
        const Vec3 old_push = model_push_n(model, state, fc.previous_model, material, seg.material,
                                           tool, dt_s, unused) +
                              blend_left() * fc.blend_offset_n;
        fc.blend_offset_n = old_push - new_push;
        if (!fc.blend_offset_n.allFinite()) {
          fc.blend_offset_n.setZero();
        }
        fc.blend_from_step = state.step_index;
        fc.adopted_this_step = false;
      }
      Vec3 f = new_push + blend_left() * fc.blend_offset_n;
      if (m.valid && !m.normal_world.isZero()) {
        // Push-only along the new model's normal, and capped there as the model itself is.
        const double along = f.dot(m.normal_world);
        const double cap = std::min(m.max_normal_force_n, std::max(material.max_force_n, 0.0));
        if (!(along > 0.0)) {
          f.setZero();
        } else if (along > cap) {
          f -= (along - cap) * m.normal_world;
        }
      }
      if (!f.allFinite() || f.isZero()) {
        continue;
      }
      fc.push_world_n = f;
      out.force_world_n += f;
      if (!(spring_n > 0.0)) {
        continue;  // only what is left of a blend from a contact let go: a ramp, not a contact
      }
      const Vec3& n = m.normal_world;
      const double k_n = n.dot(m.stiffness_n_per_m * n);
      const double depth_m = k_n > 0.0 ? spring_n / k_n : 0.0;
      if (state.contact_count < state.contacts.size()) {
        state.contacts[state.contact_count++] = WorldContact{ToolIndex{t},
                                                             BodyIndex{fem_bodies[b]},
                                                             LocalSegment{0},
                                                             tool.p_world - radius * n,
                                                             n,
                                                             depth_m,
                                                             f.dot(n),
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
