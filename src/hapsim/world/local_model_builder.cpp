#include "hapsim/world/local_model_builder.h"

#include "hapsim/deform/sheet_profile.h"
#include "hapsim/force/penalty_force.h"
#include "hapsim/world/fem_coupling.h"
#include "hapsim/world/world_step.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>

namespace hapsim {

LocalModelBuilder::LocalModelBuilder(const WorldModel& model, LocalModelBuildOptions options)
    : model_(&model), options_(options) {
  const WorldDescription& d = model.description();
  tissue_stiffness_n_per_m_.reserve(model.segments().size());
  for (const SegmentModel& seg : model.segments()) {
    double k = kInf;
    if (seg.sheet) {
      const double compliance_m_per_n =
          GaussianSheetProfile(d.bodies[seg.body].sheet_profile).depth_m(0.0, 1.0);
      k = compliance_m_per_n > 0.0 ? 1.0 / compliance_m_per_n : kInf;
    }
    tissue_stiffness_n_per_m_.push_back(k);
  }
}

// haptic path
void LocalModelBuilder::build(const WorldState& state, std::uint64_t sequence,
                              std::uint64_t device_sequence,
                              std::span<LocalContactModel> out) const noexcept {
  const std::size_t tools = std::min(out.size(), state.tool_states.size());
  for (std::size_t t = 0; t < tools; ++t) {
    LocalContactModel& m = out[t];
    const ToolState& tool = state.tool_states[t];
    m = LocalContactModel{};
    m.x0_world_m = state.tools[t].p_world;
    m.v0_world_m_per_s = state.tools[t].v_world;
    m.f0_world_n = tool.force_world_n.allFinite() ? tool.force_world_n : Vec3::Zero();
    m.validity_radius_m = options_.validity_radius_m;
    m.sim_time_s = state.time_s;
    m.sequence = sequence;
    m.device_sequence = device_sequence;
    m.valid =
        state.tools[t].input_usable && m.x0_world_m.allFinite() && m.v0_world_m_per_s.allFinite();
    m.max_normal_force_n = 0.0;  // summed over the tool's contacts below; free space: none
  }
  std::array<bool, 64> proxy_capped{};  // per tool (a world has a handful)
  for (std::size_t i = 0; i < state.contact_count; ++i) {
    const WorldContact& c = state.contacts[i];
    const std::size_t t = c.tool.index();
    if (!c.tool.valid() || t >= tools || !c.normal_world.allFinite()) {
      continue;
    }
    const std::size_t flat = model_->flat_segment(c.body, c.segment).index();
    const ContactMaterial& material = state.materials[model_->segments()[flat].material];
    LocalContactModel& m = out[t];
    const Mat3 nn = c.normal_world * c.normal_world.transpose();
    if (model_->segments()[flat].fem) {
      // A FEM body's contact already is a local model: its series stiffness (contact spring and
      // the tissue's compliance from the FEM) and its cap travel on.
      const auto& fem_bodies = model_->fem_bodies();
      const auto b = static_cast<std::size_t>(
          std::find(fem_bodies.begin(), fem_bodies.end(), c.body.index()) - fem_bodies.begin());
      const LocalContactModel& fm = state.fem_contacts[t * kMaxFemBodies + b].model;
      const double cap = std::min(fm.max_normal_force_n, material.max_force_n);
      if (c.force_n < cap * (1.0 - 1e-9)) {
        m.stiffness_n_per_m += fm.stiffness_n_per_m;
      }
      // The damping the world's stage renders it with.
      m.damping_n_s_per_m += fem_contact_damping_n_s_per_m(
                                 *model_, state.material_contact[model_->segments()[flat].material],
                                 fm, state.materials_dt_s) *
                             nn;
      m.max_normal_force_n += cap;
      if (m.normal_world.isZero()) {
        m.normal_world = c.normal_world;
      }
      continue;
    }
    // A saturated spring (at its maximum penetration or force) pushes no harder deeper in.
    const bool saturated =
        c.depth_m >= material.max_penetration_m || c.force_n >= material.max_force_n * (1.0 - 1e-9);
    if (!saturated) {
      m.stiffness_n_per_m +=
          series_stiffness_n_per_m(material.stiffness_n_per_m, tissue_stiffness_n_per_m_[flat]) *
          nn;
    }
    m.damping_n_s_per_m += std::max(material.damping_n_s_per_m, 0.0) * nn;
    // Each spring saturates at its material's force cap or at its penetration limit, whichever
    // comes first; the god-object's one spring renders its first contact's material
    // (force/god_object.h): that cap, once per tool.
    const bool counted = t < proxy_capped.size() && proxy_capped[t];
    if (!c.proxy || !counted) {
      m.max_normal_force_n += penalty_force_magnitude(material, material.max_penetration_m, 0.0);
      if (c.proxy && t < proxy_capped.size()) {
        proxy_capped[t] = true;
      }
    }
    if (m.normal_world.isZero()) {
      m.normal_world = c.normal_world;
    }
  }
  // The push-only rule follows the force the step rendered where there is one.
  for (std::size_t t = 0; t < tools; ++t) {
    if (out[t].max_normal_force_n == 0.0) {
      out[t].max_normal_force_n = std::numeric_limits<double>::infinity();  // no contact
    }
    const double f_n = out[t].f0_world_n.norm();
    if (f_n > 0.0) {
      out[t].normal_world = out[t].f0_world_n / f_n;
    }
    // The springs' caps bound the spring force; the damping on top may carry this step's force
    // a little past them (and may again): never cap below what the step itself rendered.
    out[t].max_normal_force_n = std::max(out[t].max_normal_force_n, f_n);
  }
}

}  // namespace hapsim
