#include "hapsim/world/world_step.h"

#include "hapsim/world/fem_coupling.h"
#include "hapsim/world/passivity_floor.h"
#include "hapsim/world/world_stages.h"

#include <algorithm>
#include <cmath>
#include <limits>

namespace hapsim {

ContactMaterial effective_material(const WorldModel& model, const ContactMaterial& contact,
                                   double dt_s) noexcept {
  ContactMaterial m = contact;
  if (is_rigid(contact)) {
    // Its 1e12 N·s/m is for the body-pair series law; a tool feels the device's stiffest spring,
    // damped by the passivity floor.
    m.damping_n_s_per_m = 0.0;
  }
  m.stiffness_n_per_m = std::min(m.stiffness_n_per_m, model.options().max_stiffness_n_per_m);
  m.damping_n_s_per_m =
      std::max(m.damping_n_s_per_m,
               passivity_damping_floor_n_s_per_m(model.description().passivity_damping_factor,
                                                 m.stiffness_n_per_m, dt_s));
  return m;
}

double fem_contact_damping_n_s_per_m(const WorldModel& model, const ContactMaterial& contact,
                                     const LocalContactModel& fem_model, double dt_s) noexcept {
  const Vec3& n = fem_model.normal_world;
  const double k_n = n.dot(fem_model.stiffness_n_per_m * n);
  const double b_fem = n.dot(fem_model.damping_n_s_per_m * n);
  double b = std::max(contact.damping_n_s_per_m, 0.0);
  if (std::isfinite(k_n) && k_n > 0.0) {
    b = std::max(b, passivity_damping_floor_n_s_per_m(model.description().passivity_damping_factor,
                                                      k_n, dt_s));
  }
  if (std::isfinite(b_fem) && b_fem > 0.0) {
    b = std::max(b, b_fem);
  }
  return b;
}

namespace {

// The effective materials for this dt (recomputed only when dt or a material changed).
void refresh_materials(const WorldModel& model, WorldState& state, double dt_s) noexcept {
  if (dt_s == state.materials_dt_s) {
    return;
  }
  state.materials_dt_s = dt_s;
  for (std::size_t m = 0; m < state.materials.size(); ++m) {
    state.materials[m] = effective_material(model, state.material_contact[m], dt_s);
    // Between bodies no device renders the force: no device clamp, the passivity floor only.
    ContactMaterial& body = state.body_materials[m];
    body = state.material_contact[m];
    body.damping_n_s_per_m =
        std::max(body.damping_n_s_per_m,
                 passivity_damping_floor_n_s_per_m(model.description().passivity_damping_factor,
                                                   body.stiffness_n_per_m, dt_s));
  }
}

}  // namespace

// haptic path
const StepResult& step(const WorldModel& model, WorldState& state, const DeviceInput& input,
                       double dt_s) noexcept {
  const double dt = std::isfinite(dt_s) && dt_s > 0.0 ? dt_s : 0.0;
  refresh_materials(model, state, dt);
  state.time_s += dt;
  ++state.step_index;
  if (state.fem) {
    state.fem->adopt(state, dt);  // the update due at this step, if any
  }
  state.contact_count = 0;
  state.dropped_contacts = 0;
  state.pop_throughs = 0;
  for (SegmentState& seg : state.segments) {
    seg.pending_count = 0;
    seg.sheet_push_count = 0;
  }
  for (BodyState& body : state.bodies) {
    body.force_world_n.setZero();
    body.torque_world_nm.setZero();
    if (body.dynamic) {
      body.stiffness_6.setZero();
      body.damping_6.setZero();
      body.anchor_6.setZero();
    }
  }
  for (BodyCoupling& c : state.couplings) {
    c.active = false;  // zeroed when first used this step
  }

  stage::place_tools(model, state, input, dt);
  stage::detect_contacts(model, state, dt);
  stage::body_contacts(model, state, dt);
  stage::respond(model, state, dt);
  stage::fem_contacts(model, state, dt);
  stage::integrate(model, state, dt);
  stage::deform(model, state, dt);
  stage::safety(model, state);
  if (state.fem) {
    state.fem->capture(model, state);
    if (!state.fem_deferred) {
      try {
        state.fem->run_pending();  // inline: deterministic, at the cost of this step
      } catch (...) {
        ++state.fem_failures;
      }
    }
  }
  std::fill(state.rendered_push_n.begin(), state.rendered_push_n.end(),
            std::numeric_limits<double>::quiet_NaN());  // one step's input

  StepResult& r = state.result;
  r.time_s = state.time_s;
  r.tools = state.tool_states;
  r.contacts = {state.contacts.data(), state.contact_count};
  r.command = state.command;
  r.dropped_contacts = state.dropped_contacts;
  r.body_contacts = {state.body_contacts.data(), state.body_contact_count};
  r.bodies = state.bodies;
  r.sheet_depth_m = state.sheet_depth_m;
  r.dropped_body_contacts = state.dropped_body_contacts;
  r.penalty_pop_throughs = state.pop_throughs;
  r.controller = state.controller.get();
  if (state.controller) {
    state.controller->observe(model, r);  // its reports: read-only, after the stages
  }
  return r;
}

}  // namespace hapsim
