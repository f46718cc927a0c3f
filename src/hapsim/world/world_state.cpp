#include "hapsim/world/world_state.h"

#include "hapsim/world/fem_coupling.h"

#include "hapsim/collision/knee_index.h"
#include "hapsim/collision/mesh_bvh.h"
#include "hapsim/collision/sphere_tree.h"
#include "hapsim/core/error.h"
#include "hapsim/deform/sheet_query.h"
#include "hapsim/world/world_model.h"

#include <algorithm>

namespace hapsim {

namespace {

// J = [I, −[r]×]: the velocity of the point r from a body's centre of mass.
Eigen::Matrix<double, 3, 6> point_jacobian(const Vec3& r) {
  Mat3 r_cross;
  r_cross << 0.0, -r.z(), r.y(), r.z(), 0.0, -r.x(), -r.y(), r.x(), 0.0;
  Eigen::Matrix<double, 3, 6> J;
  J << Mat3::Identity(), -r_cross;
  return J;
}

}  // namespace

// haptic path
void WorldState::couple_bodies(const WorldModel& model, std::size_t body_a, std::size_t body_b,
                               const Vec3& p_a_world, const Vec3& p_b_world, const Mat3& S,
                               const Mat3& D) noexcept {
  const std::int32_t i = model.bodies()[body_a].dynamic_index;
  const std::int32_t j = model.bodies()[body_b].dynamic_index;
  if (i < 0 || j < 0 || couplings.empty()) {
    return;
  }
  const auto n = static_cast<std::size_t>(model.dynamic_bodies().size());
  const Eigen::Matrix<double, 3, 6> J_a =
      point_jacobian(p_a_world - bodies[body_a].com_world(model.bodies()[body_a].com_body));
  const Eigen::Matrix<double, 3, 6> J_b =
      point_jacobian(p_b_world - bodies[body_b].com_world(model.bodies()[body_b].com_body));
  BodyCoupling& ab = couplings[static_cast<std::size_t>(i) * n + static_cast<std::size_t>(j)];
  BodyCoupling& ba = couplings[static_cast<std::size_t>(j) * n + static_cast<std::size_t>(i)];
  for (BodyCoupling* c : {&ab, &ba}) {
    if (!c->active) {
      c->stiffness_6.setZero();
      c->damping_6.setZero();
      c->active = true;
    }
  }
  // F_a = −S·(x_a − x_b) at the points: ∂F_a/∂x_b = J_aᵀ·S·J_b, and the mirror for b.
  ab.stiffness_6.noalias() += J_a.transpose() * S * J_b;
  ab.damping_6.noalias() += J_a.transpose() * D * J_b;
  ba.stiffness_6.noalias() += J_b.transpose() * S * J_a;
  ba.damping_6.noalias() += J_b.transpose() * D * J_a;
}

// haptic path
void WorldState::couple_rotations(const WorldModel& model, std::size_t body_a, std::size_t body_b,
                                  const Mat3& D) noexcept {
  const std::int32_t i = model.bodies()[body_a].dynamic_index;
  const std::int32_t j = model.bodies()[body_b].dynamic_index;
  if (i < 0 || j < 0 || couplings.empty()) {
    return;
  }
  const auto n = static_cast<std::size_t>(model.dynamic_bodies().size());
  for (BodyCoupling* c :
       {&couplings[static_cast<std::size_t>(i) * n + static_cast<std::size_t>(j)],
        &couplings[static_cast<std::size_t>(j) * n + static_cast<std::size_t>(i)]}) {
    if (!c->active) {
      c->stiffness_6.setZero();
      c->damping_6.setZero();
      c->active = true;
    }
    c->damping_6.bottomRightCorner<3, 3>() += D;
  }
}

// haptic path
void BodyState::add_contact_spring(const Vec3& p_world, const Vec3& com_body, const Mat3& S,
                                   const Mat3& D, const Vec3& v_anchor_world) noexcept {
  if (!dynamic) {
    return;
  }
  // The point's velocity is J·[v; ω] with J = [I, −[r]×]; a force f there is Jᵀ·f on the body.
  const Eigen::Matrix<double, 3, 6> J = point_jacobian(p_world - com_world(com_body));
  stiffness_6.noalias() += J.transpose() * S * J;
  damping_6.noalias() += J.transpose() * D * J;
  anchor_6.noalias() += J.transpose() * (S * v_anchor_world);
}

namespace {

// Every body at its start pose and velocity.
void place_bodies(const WorldModel& model, std::vector<BodyState>& bodies) {
  const WorldDescription& d = model.description();
  bodies.assign(d.bodies.size(), BodyState{});
  for (std::size_t b = 0; b < d.bodies.size(); ++b) {
    BodyState& body = bodies[b];
    body.X_world_body = d.bodies[b].X_world_body;
    body.X_body_world = body.X_world_body.inverse();
    if (d.bodies[b].kind == BodyKind::kDynamic) {
      body.dynamic = true;
      body.v_world = d.bodies[b].rigid.v_world;
      body.w_world = d.bodies[b].rigid.w_world;
    }
  }
}

}  // namespace

WorldState::WorldState(const WorldModel& model) {
  const WorldDescription& d = model.description();
  const std::size_t tool_count = model.tool_count();
  const std::vector<SegmentModel>& segs = model.segments();
  segments.resize(segs.size());
  place_bodies(model, bodies);
  body_pairs.resize(model.dynamic_segments().size() * segs.size());
  if (model.dynamic_bodies().size() > 1) {
    couplings.resize(model.dynamic_bodies().size() * model.dynamic_bodies().size());
  }
  if (model.has_dynamic_meshes()) {
    leaf_pairs.reserve(kMaxBodyLeafPairs);
    for (std::size_t i = 0; i < segs.size(); ++i) {
      segments[i].vertex_pass.assign(segs[i].description->mesh.vertex_count(), 0);
    }
  }
  body_contacts.resize(std::max<std::size_t>(body_pairs.size(), 1));
  sheet_depth_m.assign(
      static_cast<std::size_t>(
          std::count_if(segs.begin(), segs.end(), [](const SegmentModel& s) { return s.sheet; })),
      0.0);
  for (std::size_t i = 0; i < segs.size(); ++i) {
    const SegmentModel& seg = segs[i];
    if (seg.sheet) {
      const BodyDescription& body = d.bodies[seg.body];
      try {
        segments[i].sheet = std::make_unique<VirtualSheet>(
            body.sheet, std::make_unique<GaussianSheetProfile>(body.sheet_profile));
      } catch (const Error& e) {
        throw Error("body '" + body.name + "'", e.what());
      }
      segments[i].sheet_query = std::make_unique<SheetQuery>(*segments[i].sheet);
      segments[i].sheet_pushes.resize(tool_count + model.dynamic_segments().size() + 1);
      continue;
    }
    if (!seg.deformable) {
      continue;
    }
    const SegmentDescription& sd = *seg.description;
    VertexDeflectionOptions dopt;
    dopt.segments = {d.materials[sd.material].deflection};
    dopt.typical_contact_radius_m = model.max_tool_radius_m();
    if (seg.rest_query->method_name() == "knee") {
      // The knee paper moves vertices along their group's radial direction.
      const auto& knee = static_cast<const KneeIndex&>(*seg.rest_query);
      dopt.directions.resize(sd.mesh.vertex_count());
      for (std::uint32_t v = 0; v < sd.mesh.vertex_count(); ++v) {
        dopt.directions[v] = -knee.radial_direction(v);
      }
    }
    try {
      segments[i].deflection = std::make_unique<VertexDeflection>(sd.mesh, std::move(dopt));
    } catch (const Error& e) {
      throw Error("body '" + d.bodies[seg.body].name + "' segment '" + sd.name + "'", e.what());
    }
    segments[i].pending.resize(std::max<std::size_t>(tool_count * GodObject::kMaxContacts, 1));
  }
  for (std::size_t t = 0; t < tool_count; ++t) {
    GodObjectParams gp;
    gp.radius_m = d.tools[t].radius_m;
    gp.max_substep_m = model.options().proxy_max_substep_m;
    gp.max_iterations = model.options().proxy_max_iterations;
    ToolRuntime tool;
    tool.proxy = GodObject(gp);
    tool.hints.resize(segs.size());
    tool.near_last_step.assign(segs.size(), 0);
    tool.penalty_side.assign(segs.size(), PenaltySide{});
    tool.own_dent.assign(segs.size(), OwnDent{});
    tool.felt_dent_m.assign(segs.size(), 0.0);
    tool.pressing.assign(segs.size(), 0);
    tool.stick_body.assign(segs.size(), StickPoint{});
    tool.penalty.resize(std::max<std::size_t>(model.penalty_segment_count(), 1));
    tools.push_back(std::move(tool));
  }
  // The proxy surfaces point into this state's hints and materials: set up once the vectors have
  // their final size (they never reallocate afterwards).
  material_contact.reserve(d.materials.size());
  for (const MaterialDescription& m : d.materials) {
    material_contact.push_back(m.contact);
  }
  materials.resize(d.materials.size());
  body_materials.resize(d.materials.size());
  for (ToolRuntime& tool : tools) {
    for (std::size_t i = 0; i < segs.size(); ++i) {
      const SegmentModel& seg = segs[i];
      if (seg.response != ContactResponse::kProxy || seg.fem) {
        continue;
      }
      tool.surfaces.push_back(ProxySurface{seg.rest_query.get(), seg.X_world_body,
                                           &materials[seg.material], seg.description->two_sided,
                                           &tool.hints[i]});
      tool.surface_segment.push_back(i);
    }
  }
  tool_states.resize(tool_count);
  rendered_push_n.assign(tool_count, std::numeric_limits<double>::quiet_NaN());
  // Per tool: at most kMaxContacts proxy contacts plus one per penalty segment and FEM body.
  contacts.resize(std::max<std::size_t>(
      tool_count * (static_cast<std::size_t>(GodObject::kMaxContacts) +
                    model.penalty_segment_count() + model.fem_bodies().size()),
      1));
  if (!model.fem_bodies().empty()) {
    fem_contacts.assign(tool_count * kMaxFemBodies, FemToolContact{});
    fem = std::make_unique<FemCoupling>(model);
  }
  if (d.controller) {
    controller = d.controller->make_state(model);
  }
  result.tools = tool_states;
  result.contacts = {contacts.data(), 0};
  result.body_contacts = {body_contacts.data(), 0};
  result.bodies = bodies;
  result.sheet_depth_m = sheet_depth_m;
  result.controller = controller.get();
  model_ = &model;
}

WorldState::~WorldState() = default;

void WorldState::reset() {
  tools_placed = false;
  time_s = 0.0;
  step_index = 0;
  for (ToolRuntime& tool : tools) {
    tool.has_previous = false;
    for (QueryHint& h : tool.hints) {
      h = QueryHint{};
    }
    for (PenaltySide& side : tool.penalty_side) {
      side = PenaltySide{};
    }
    std::fill(tool.near_last_step.begin(), tool.near_last_step.end(), std::uint8_t{0});
    std::fill(tool.own_dent.begin(), tool.own_dent.end(), OwnDent{});
    std::fill(tool.felt_dent_m.begin(), tool.felt_dent_m.end(), 0.0);
    std::fill(tool.pressing.begin(), tool.pressing.end(), std::uint8_t{0});
    std::fill(tool.stick_body.begin(), tool.stick_body.end(), StickPoint{});
  }
  for (SegmentState& seg : segments) {
    if (seg.deflection) {
      seg.deflection->reset();
      seg.deformed_dirty = true;
    }
    if (seg.sheet) {
      seg.sheet->reset();
      seg.sheet_push_count = 0;
      seg.sheet_dirty = true;
    }
  }
  place_bodies(*model_, bodies);
  std::fill(body_pairs.begin(), body_pairs.end(), BodyPairState{});
  for (SegmentState& seg : segments) {
    std::fill(seg.vertex_pass.begin(), seg.vertex_pass.end(), 0);
  }
  vertex_pass = 0;
  std::fill(sheet_depth_m.begin(), sheet_depth_m.end(), 0.0);
  body_contact_count = 0;
  std::fill(fem_contacts.begin(), fem_contacts.end(), FemToolContact{});
  if (fem) {
    fem->reset();
  }
  for (ToolState& state : tool_states) {
    state = ToolState{};
  }
  if (controller) {
    controller->reset();
  }
  contact_count = 0;
  result = StepResult{};
  result.tools = tool_states;
  result.contacts = {contacts.data(), 0};
  result.body_contacts = {body_contacts.data(), 0};
  result.bodies = bodies;
  result.sheet_depth_m = sheet_depth_m;
  result.controller = controller.get();
}

}  // namespace hapsim
