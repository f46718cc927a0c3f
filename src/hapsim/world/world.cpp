#include "hapsim/world/world.h"

#include "hapsim/collision/csg_query.h"
#include "hapsim/collision/knee_index.h"
#include "hapsim/collision/mesh_bvh.h"
#include "hapsim/collision/sphere_tree.h"
#include "hapsim/core/error.h"
#include "hapsim/core/stopwatch.h"
#include "hapsim/deform/vertex_deflection.h"
#include "hapsim/force/penalty_force.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>

namespace hapsim {

std::string_view to_string(ContactResponse response) {
  return response == ContactResponse::kProxy ? "proxy" : "penalty";
}

std::string_view to_string(ContactMethod method) {
  switch (method) {
    case ContactMethod::kExact:
      return "exact";
    case ContactMethod::kSphereTree:
      return "spheretree";
    case ContactMethod::kKnee:
      return "knee";
  }
  return "unknown";
}

std::optional<ContactMethod> parse_contact_method(std::string_view name) {
  for (const ContactMethod m :
       {ContactMethod::kExact, ContactMethod::kSphereTree, ContactMethod::kKnee}) {
    if (name == to_string(m)) {
      return m;
    }
  }
  return std::nullopt;
}

std::string_view to_string(BodyKind kind) {
  switch (kind) {
    case BodyKind::kStatic:
      return "static";
    case BodyKind::kDynamic:
      return "dynamic";
    case BodyKind::kDeformable:
      return "deformable";
  }
  return "unknown";
}

struct World::Segment {
  std::size_t body = 0;
  std::size_t index_in_body = 0;
  const SegmentDescription* description = nullptr;
  std::uint32_t material = 0;
  ContactResponse response = ContactResponse::kProxy;
  Iso3 X_world_body = Iso3::Identity();
  Iso3 X_body_world = Iso3::Identity();
  Box3 rest_bounds_body;
  std::unique_ptr<ProximityQuery> rest_query;
  std::unique_ptr<VertexDeflection> deflection;  // deformable bodies only
  std::unique_ptr<MeshBvh> deformed_bvh;         // built on first deformed_query()
  bool deformed_dirty = false;
  std::vector<DeflectionContact> pending;  // this step's contacts, capacity = tool count
  std::size_t pending_count = 0;
};

struct World::Tool {
  GodObject proxy;
  std::vector<ProxySurface> surfaces;        // one per proxy segment
  std::vector<std::size_t> surface_segment;  // flat segment of each surface
  std::vector<QueryHint> hints;              // one per flat segment (temporal coherence)
  // Per flat segment: the tool was within reach of, or inside, it last step. Only then can it be
  // deeper than the reach now (it moves far less than a reach per cycle), so only then is the
  // costly deep-inside query needed.
  std::vector<std::uint8_t> near_last_step;
  Vec3 p_previous_world = Vec3::Zero();
  bool has_previous = false;
};

namespace {

// A CSG segment always answers from its solid's signed distance (exact, and cheaper than any
// mesh structure), whatever the body's method: the method names how a *mesh* is searched, and
// the polygonised mesh only approximates the solid (edges bevelled by about a cell).
std::unique_ptr<ProximityQuery> make_query(ContactMethod method,
                                           const SegmentDescription& segment) {
  if (segment.csg) {
    return std::make_unique<CsgQuery>(*segment.csg, segment.mesh);
  }
  const TriangleMesh& mesh = segment.mesh;
  switch (method) {
    case ContactMethod::kSphereTree:
      return std::make_unique<SphereTree>(mesh);
    case ContactMethod::kKnee:
      return std::make_unique<KneeIndex>(mesh);
    case ContactMethod::kExact:
      break;
  }
  return std::make_unique<MeshBvh>(mesh);
}

// FNV-1a, 64 bit: a stable content fingerprint (not a security hash).
class Fnv64 {
 public:
  void bytes(const void* data, std::size_t n) {
    const auto* p = static_cast<const unsigned char*>(data);
    for (std::size_t i = 0; i < n; ++i) {
      h_ = (h_ ^ p[i]) * 1099511628211ULL;
    }
  }
  void number(double x) { bytes(&x, sizeof x); }
  void text(const std::string& s) {
    bytes(s.data(), s.size());
    number(static_cast<double>(s.size()));
  }
  [[nodiscard]] std::uint64_t value() const { return h_; }

 private:
  std::uint64_t h_ = 14695981039346656037ULL;
};

}  // namespace

World::World(WorldDescription description, WorldOptions options)
    : description_(std::move(description)), options_(options) {
  const Stopwatch watch;
  if (description_.has_hand) {
    hand_ = std::make_unique<HandModel>(description_.hand);
    for (const ToolDescription& t : description_.tools) {
      if (t.finger < 0 || t.finger >= kHandFingers) {
        throw Error("tool '" + t.name + "'",
                    "a glove drives the tools: expected a finger 0 (thumb) .. 4 (little)");
      }
    }
  }
  const std::size_t tool_count = description_.tools.size();
  double max_tool_radius_m = 0.0;
  for (const ToolDescription& t : description_.tools) {
    max_tool_radius_m = std::max(max_tool_radius_m, t.radius_m);
  }
  for (std::size_t b = 0; b < description_.bodies.size(); ++b) {
    const BodyDescription& body = description_.bodies[b];
    body_first_segment_.push_back(segments_.size());
    if (body.segments.empty()) {
      throw Error("body '" + body.name + "'", "has no segments");
    }
    for (std::size_t s = 0; s < body.segments.size(); ++s) {
      const SegmentDescription& sd = body.segments[s];
      const std::string where = "body '" + body.name + "' segment '" + sd.name + "'";
      if (sd.mesh.empty()) {
        throw Error(where, "has an empty mesh");
      }
      if (sd.material >= description_.materials.size()) {
        throw Error(where, "refers to material " + std::to_string(sd.material) + " of " +
                               std::to_string(description_.materials.size()));
      }
      auto seg = std::make_unique<Segment>();
      seg->body = b;
      seg->index_in_body = s;
      seg->description = &sd;
      seg->material = sd.material;
      seg->response = description_.materials[sd.material].response;
      seg->X_world_body = body.X_world_body;
      seg->X_body_world = body.X_world_body.inverse();
      seg->rest_bounds_body = sd.mesh.bounds();
      seg->rest_query = make_query(body.method, sd);
      if (body.kind == BodyKind::kDeformable) {
        VertexDeflectionOptions dopt;
        dopt.segments = {description_.materials[sd.material].deflection};
        dopt.typical_contact_radius_m = max_tool_radius_m;
        if (body.method == ContactMethod::kKnee && !sd.csg) {
          // The knee paper moves vertices along their group's radial direction.
          const auto& knee = static_cast<const KneeIndex&>(*seg->rest_query);
          dopt.directions.resize(sd.mesh.vertex_count());
          for (std::uint32_t v = 0; v < sd.mesh.vertex_count(); ++v) {
            dopt.directions[v] = -knee.radial_direction(v);
          }
        }
        try {
          seg->deflection = std::make_unique<VertexDeflection>(sd.mesh, std::move(dopt));
        } catch (const Error& e) {
          throw Error(where, e.what());
        }
        seg->pending.resize(std::max<std::size_t>(tool_count * GodObject::kMaxContacts, 1));
      }
      segments_.push_back(std::move(seg));
    }
  }
  std::size_t proxy_segments = 0;
  std::size_t penalty_segments = 0;
  for (const auto& seg : segments_) {
    (seg->response == ContactResponse::kProxy ? proxy_segments : penalty_segments) += 1;
  }
  if (proxy_segments > static_cast<std::size_t>(GodObject::kMaxSurfaces)) {
    throw Error("world '" + description_.name + "'",
                "has " + std::to_string(proxy_segments) + " proxy segments; at most " +
                    std::to_string(GodObject::kMaxSurfaces) + " are supported");
  }
  for (std::size_t t = 0; t < tool_count; ++t) {
    const ToolDescription& td = description_.tools[t];
    if (!(td.radius_m >= 0.0) || !std::isfinite(td.radius_m) || !td.offset_device.allFinite()) {
      throw Error("tool '" + td.name + "'", "needs a finite radius >= 0 and a finite offset");
    }
    if (td.finger >= kMaxFingers) {
      throw Error("tool '" + td.name + "'",
                  "finger must be below " + std::to_string(kMaxFingers) + " (or -1)");
    }
    GodObjectParams gp;
    gp.radius_m = td.radius_m;
    gp.max_substep_m = options_.proxy_max_substep_m;
    gp.max_iterations = options_.proxy_max_iterations;
    auto tool = std::make_unique<Tool>();
    tool->proxy = GodObject(gp);
    tool->hints.resize(segments_.size());
    tool->near_last_step.assign(segments_.size(), 0);
    for (std::size_t i = 0; i < segments_.size(); ++i) {
      const Segment& seg = *segments_[i];
      if (seg.response != ContactResponse::kProxy) {
        continue;
      }
      tool->surfaces.push_back(ProxySurface{seg.rest_query.get(), seg.X_world_body, nullptr,
                                            seg.description->two_sided, &tool->hints[i]});
      tool->surface_segment.push_back(i);
    }
    tools_.push_back(std::move(tool));
  }
  tool_states_.resize(tool_count);
  // Per tool: at most kMaxContacts proxy contacts plus one per penalty segment.
  contacts_.resize(std::max<std::size_t>(
      tool_count * (static_cast<std::size_t>(GodObject::kMaxContacts) + penalty_segments), 1));
  materials_.resize(description_.materials.size());
  update_materials(1e-3);
  result_.tools = tool_states_;
  result_.contacts = {contacts_.data(), 0};
  build_ms_ = watch.elapsed_ms();
}

World::~World() = default;

std::size_t World::segment_count(std::size_t body) const {
  return description_.bodies.at(body).segments.size();
}

std::size_t World::flat_segment(std::size_t body, std::size_t segment) const {
  return body_first_segment_.at(body) + segment;
}

const ProximityQuery& World::rest_query(std::size_t body, std::size_t segment) const {
  return *segments_.at(flat_segment(body, segment))->rest_query;
}

const TriangleMesh& World::surface(std::size_t body, std::size_t segment) const {
  const Segment& seg = *segments_.at(flat_segment(body, segment));
  return seg.deflection ? seg.deflection->mesh() : seg.description->mesh;
}

const ProximityQuery& World::deformed_query(std::size_t body, std::size_t segment) {
  Segment& seg = *segments_.at(flat_segment(body, segment));
  if (!seg.deflection) {
    return *seg.rest_query;
  }
  if (!seg.deformed_bvh) {
    seg.deformed_bvh = std::make_unique<MeshBvh>(seg.deflection->mesh());
  } else if (seg.deformed_dirty) {
    seg.deformed_bvh->refit();
  }
  seg.deformed_dirty = false;
  return *seg.deformed_bvh;
}

const VertexDeflection* World::deflection(std::size_t body, std::size_t segment) const {
  return segments_.at(flat_segment(body, segment))->deflection.get();
}

double World::current_deflection_m(std::size_t body, std::size_t segment) const {
  const Segment& seg = *segments_.at(flat_segment(body, segment));
  return seg.deflection ? seg.deflection->max_deflection_m() : 0.0;
}

ContactMaterial World::effective_material(std::uint32_t material, double dt_s) const {
  ContactMaterial m = description_.materials.at(material).contact;
  m.stiffness_n_per_m = std::min(m.stiffness_n_per_m, options_.max_stiffness_n_per_m);
  const double dt = std::isfinite(dt_s) && dt_s > 0.0 ? dt_s : 0.0;
  m.damping_n_s_per_m = std::max(m.damping_n_s_per_m,
                                 description_.passivity_damping_factor * m.stiffness_n_per_m * dt);
  return m;
}

void World::forget_tool_motion() noexcept {
  for (auto& tool : tools_) {
    tool->has_previous = false;
  }
}

bool World::set_material_contact(std::uint32_t material, const ContactMaterial& c) noexcept {
  const auto positive = [](double v) { return std::isfinite(v) && v > 0.0; };
  const auto non_negative = [](double v) { return std::isfinite(v) && v >= 0.0; };
  if (material >= description_.materials.size() || !positive(c.stiffness_n_per_m) ||
      !positive(c.max_penetration_m) || !positive(c.max_force_n) ||
      !non_negative(c.damping_n_s_per_m) || !non_negative(c.static_friction) ||
      !non_negative(c.dynamic_friction) || c.dynamic_friction > c.static_friction) {
    return false;
  }
  description_.materials[material].contact = c;
  materials_dt_s_ = -1.0;  // the next step recomputes the effective materials
  return true;
}

void World::update_materials(double dt_s) {
  if (dt_s == materials_dt_s_) {
    return;
  }
  materials_dt_s_ = dt_s;
  for (std::uint32_t m = 0; m < materials_.size(); ++m) {
    materials_[m] = effective_material(m, dt_s);
  }
  for (auto& tool : tools_) {
    for (std::size_t i = 0; i < tool->surfaces.size(); ++i) {
      tool->surfaces[i].material = &materials_[segments_[tool->surface_segment[i]]->material];
    }
  }
}

void World::add_contact(const WorldContact& contact) {
  if (contact_count_ < contacts_.size()) {
    contacts_[contact_count_++] = contact;
  } else {
    ++dropped_contacts_;
  }
}

// haptic path
void World::step_tool(std::size_t t, const Vec3& p_world, double dt_s) {
  Tool& tool = *tools_[t];
  ToolState& state = tool_states_[t];
  const double radius = description_.tools[t].radius_m;
  const Vec3 v_world = tool.has_previous && dt_s > 0.0
                           ? Vec3((p_world - tool.p_previous_world) / dt_s)
                           : Vec3::Zero();
  const double moved_m = tool.has_previous ? (p_world - tool.p_previous_world).norm() : kInf;
  tool.p_previous_world = p_world;
  tool.has_previous = true;
  state.p_world = p_world;
  state.contact_count = 0;

  // 1. Proxy segments.
  tool.proxy.update(p_world, tool.surfaces);
  const Vec3 proxy_force_world = proxy_force(tool.proxy, tool.surfaces, p_world, v_world);
  Vec3 total = proxy_force_world;
  state.proxy_world = tool.proxy.proxy_world();
  bool first = true;
  for (const ProxyContact& c : tool.proxy.contacts()) {
    Segment& seg = *segments_[tool.surface_segment[static_cast<std::size_t>(c.surface)]];
    const double depth = std::max(0.0, (tool.proxy.proxy_world() - p_world).dot(c.normal_world));
    // proxy_force() renders the first contact's material along the spring; report it there.
    add_contact(WorldContact{static_cast<std::int32_t>(t), static_cast<std::int32_t>(seg.body),
                             static_cast<std::int32_t>(seg.index_in_body), c.point_world,
                             c.normal_world, depth, first ? proxy_force_world.norm() : 0.0, true});
    first = false;
    ++state.contact_count;
    if (seg.deflection && depth > 0.0 && seg.pending_count < seg.pending.size()) {
      seg.pending[seg.pending_count++] =
          DeflectionContact{seg.X_body_world * c.point_world, depth, radius, 0};
    }
  }

  // 2. Penalty segments, at the tool's own position.
  for (std::size_t i = 0; i < segments_.size(); ++i) {
    Segment& seg = *segments_[i];
    if (seg.response != ContactResponse::kPenalty) {
      continue;
    }
    const ContactMaterial& material = materials_[seg.material];
    const Vec3 p_body = seg.X_body_world * p_world;
    const double reach = radius + std::max(material.max_penetration_m, 0.0);
    // Cheap cull: outside the rest bounds grown by the reach nothing can touch.
    if ((p_body - p_body.cwiseMax(seg.rest_bounds_body.min()).cwiseMin(seg.rest_bounds_body.max()))
            .squaredNorm() > reach * reach) {
      continue;
    }
    SurfacePoint sp;
    std::uint8_t& near = tool.near_last_step[i];
    if (!seg.rest_query->contact_within(p_body, reach, &sp, &tool.hints[i])) {
      // Either clear of the surface or deeper inside than the reach (saturated spring). Deeper
      // is only possible inside the bounds, and only for a tool that was near or inside last
      // step or has moved more than a reach since (a first cycle, a jump).
      if (!seg.rest_bounds_body.contains(p_body) || (near == 0 && moved_m < reach)) {
        near = 0;
        continue;
      }
      sp = seg.rest_query->closest_point(p_body, &tool.hints[i]);
      if (!(sp.signed_distance < 0.0)) {
        near = 0;
        continue;
      }
    }
    near = 1;
    const double depth = radius - sp.signed_distance;
    if (!(depth > 0.0) || !std::isfinite(depth)) {
      continue;
    }
    const Vec3 n_world = seg.X_world_body.linear() * sp.normal;
    const Vec3 f = penalty_force(material, depth, n_world, -v_world.dot(n_world));
    total += f;
    add_contact(WorldContact{static_cast<std::int32_t>(t), static_cast<std::int32_t>(seg.body),
                             static_cast<std::int32_t>(seg.index_in_body),
                             seg.X_world_body * sp.point, n_world, depth, f.norm(), false});
    ++state.contact_count;
    if (seg.deflection && seg.pending_count < seg.pending.size()) {
      seg.pending[seg.pending_count++] = DeflectionContact{sp.point, depth, radius, 0};
    }
  }
  state.force_world_n = total.allFinite() ? total : Vec3::Zero();
}

// haptic path
const StepResult& World::step(const DeviceInput& input, double dt_s) {
  const double dt = std::isfinite(dt_s) && dt_s > 0.0 ? dt_s : 0.0;
  update_materials(dt);
  time_s_ += dt;
  contact_count_ = 0;
  dropped_contacts_ = 0;
  for (auto& seg : segments_) {
    seg->pending_count = 0;
  }
  const bool usable = input.healthy && input.p_world.allFinite() &&
                      input.q_world.coeffs().allFinite() && input.q_world.squaredNorm() > 0.5;
  DeviceCommand command;
  if (usable) {
    const Quat q = input.q_world.normalized();
    std::array<Vec3, kHandFingers> tips{};
    if (hand_) {
      Iso3 X_world_hand = Iso3::Identity();
      X_world_hand.linear() = q.toRotationMatrix();
      X_world_hand.translation() = input.p_world;
      tips = hand_->fingertips_world(glove_reading(
          X_world_hand, {input.joint_rad.data(), static_cast<std::size_t>(std::clamp(
                                                     input.joint_count, 0, kMaxDeviceJoints))}));
    }
    for (std::size_t t = 0; t < tools_.size(); ++t) {
      const Vec3 p_world = hand_ ? tips[static_cast<std::size_t>(description_.tools[t].finger)]
                                 : Vec3(input.p_world + q * description_.tools[t].offset_device);
      if (!tools_placed_) {
        tools_[t]->proxy.reset(p_world);
      }
      step_tool(t, p_world, dt);
      const int finger = description_.tools[t].finger;
      if (finger >= 0) {
        auto& f = command.finger_force_n[static_cast<std::size_t>(finger)];
        f = std::max(f, tool_states_[t].force_world_n.norm());
        command.finger_count = std::max(command.finger_count, finger + 1);
      } else {
        command.force_world_n += tool_states_[t].force_world_n;
      }
    }
    tools_placed_ = true;
  } else {
    for (auto& state : tool_states_) {
      state.force_world_n.setZero();
      state.contact_count = 0;
    }
    for (auto& tool : tools_) {
      tool->has_previous = false;  // no velocity spike when the input comes back
    }
  }
  // 4. Deformation: contacts deflect, everything else recovers.
  for (auto& seg : segments_) {
    if (!seg->deflection) {
      continue;
    }
    seg->deflection->step({seg->pending.data(), seg->pending_count}, dt);
    if (!seg->deflection->moved_vertices().empty()) {
      seg->deformed_dirty = true;
    }
  }
  result_.time_s = time_s_;
  result_.tools = tool_states_;
  result_.contacts = {contacts_.data(), contact_count_};
  result_.command = command;
  result_.dropped_contacts = dropped_contacts_;
  return result_;
}

void World::reset() {
  tools_placed_ = false;
  time_s_ = 0.0;
  for (auto& tool : tools_) {
    tool->has_previous = false;
    for (QueryHint& h : tool->hints) {
      h = QueryHint{};
    }
  }
  for (auto& seg : segments_) {
    if (seg->deflection) {
      seg->deflection->reset();
      seg->deformed_dirty = true;
    }
  }
  for (auto& state : tool_states_) {
    state = ToolState{};
  }
  contact_count_ = 0;
  result_ = StepResult{};
  result_.tools = tool_states_;
  result_.contacts = {contacts_.data(), 0};
}

std::string World::content_hash() const {
  return hapsim::content_hash(description_);
}

std::string content_hash(const WorldDescription& description_) {
  Fnv64 h;
  h.text(description_.name);
  for (const MaterialDescription& m : description_.materials) {
    h.text(m.name);
    const ContactMaterial& c = m.contact;
    for (double x : {c.stiffness_n_per_m, c.max_penetration_m, c.max_force_n, c.damping_n_s_per_m,
                     c.static_friction, c.dynamic_friction, m.deflection.elasticity_factor,
                     m.deflection.recovery_time_constant_s, m.deflection.max_recovery_speed_m_per_s,
                     m.deflection.max_deflection_m}) {
      h.number(x);
    }
    h.number(static_cast<double>(m.response));
  }
  for (const BodyDescription& b : description_.bodies) {
    h.text(b.name);
    h.number(static_cast<double>(b.kind));
    h.number(static_cast<double>(b.method));
    h.bytes(b.X_world_body.matrix().data(), sizeof(double) * 16);
    for (const SegmentDescription& s : b.segments) {
      h.text(s.name);
      h.number(s.material);
      h.number(s.two_sided ? 1.0 : 0.0);
      if (s.csg) {
        // Contact comes from the solid, not the mesh; the mesh (hashed below) polygonises it.
        h.text("csg");
        h.number(static_cast<double>(s.csg->node_count()));
      }
      for (const Vec3& v : s.mesh.vertices) {
        h.bytes(v.data(), sizeof(double) * 3);
      }
      for (const TriangleIndices& tri : s.mesh.triangles) {
        h.bytes(tri.data(), sizeof(std::uint32_t) * 3);
      }
    }
  }
  for (const ToolDescription& t : description_.tools) {
    h.text(t.name);
    h.number(t.radius_m);
    h.bytes(t.offset_device.data(), sizeof(double) * 3);
    h.number(t.finger);
  }
  h.number(description_.passivity_damping_factor);
  h.number(description_.has_hand ? description_.hand.dip_per_pip : -1.0);
  char buffer[32];
  std::snprintf(buffer, sizeof buffer, "%016llx", static_cast<unsigned long long>(h.value()));
  return buffer;
}

std::size_t World::query_memory_bytes() const {
  std::size_t bytes = 0;
  for (const auto& seg : segments_) {
    bytes += seg->rest_query->memory_bytes();
  }
  return bytes;
}

}  // namespace hapsim
