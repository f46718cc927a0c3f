#include "hapsim/world/world.h"

#include "hapsim/collision/mesh_bvh.h"
#include "hapsim/core/stopwatch.h"
#include "hapsim/deform/vertex_deflection.h"
#include "hapsim/world/fem_coupling.h"
#include "hapsim/world/world_step.h"

#include <algorithm>
#include <cmath>

namespace hapsim {

World::World(WorldDescription description, WorldOptions options)
    : model_(std::move(description), options), state_(model_) {
  // Effective materials exist before the first step (effective_material() and the proxies read
  // them); the step recomputes them for its own dt.
  for (std::size_t m = 0; m < state_.materials.size(); ++m) {
    state_.materials[m] = hapsim::effective_material(model_, state_.material_contact[m], 1e-3);
  }
  state_.materials_dt_s = -1.0;  // the first step fills every material table for its own dt
  build_ms_ = build_watch_.elapsed_ms();
}

World::~World() = default;

const StepResult& World::step(const DeviceInput& input, double dt_s) {
  return hapsim::step(model_, state_, input, dt_s);
}

void World::reset() {
  state_.reset();
}

std::size_t World::segment_count(std::size_t body) const {
  return description().bodies.at(body).segments.size();
}

FlatSegment World::flat_segment(BodyIndex body, LocalSegment segment) const {
  return model_.flat_segment(body, segment);
}

namespace {

// The flat index of the World API's plain (body, segment) pair.
std::size_t flat_of(const WorldModel& model, std::size_t body, std::size_t segment) {
  return model.flat_segment(BodyIndex{body}, LocalSegment{segment}).index();
}

}  // namespace

const ProximityQuery& World::rest_query(std::size_t body, std::size_t segment) const {
  return *model_.segments().at(flat_of(model_, body, segment)).rest_query;
}

const TriangleMesh& World::surface(std::size_t body, std::size_t segment) const {
  const std::size_t flat = flat_of(model_, body, segment);
  const SegmentState& seg = state_.segments.at(flat);
  if (seg.sheet) {
    return seg.sheet->mesh();
  }
  if (model_.segments()[flat].fem && state_.fem) {
    const auto& fem_bodies = model_.fem_bodies();
    const auto it = std::find(fem_bodies.begin(), fem_bodies.end(), body);
    return state_.fem->surface(static_cast<std::size_t>(it - fem_bodies.begin()));
  }
  return seg.deflection ? seg.deflection->mesh() : model_.segments()[flat].description->mesh;
}

void World::set_fem_deferred(bool deferred) noexcept {
  state_.fem_deferred = deferred;
}

bool World::advance_fem() {
  return state_.fem && state_.fem->run_pending();
}

const VirtualSheet* World::sheet(std::size_t body) const {
  const std::size_t flat = flat_of(model_, body, 0);
  return state_.segments.at(flat).sheet.get();
}

const ProximityQuery& World::deformed_query(std::size_t body, std::size_t segment) {
  const std::size_t flat = flat_of(model_, body, segment);
  SegmentState& seg = state_.segments.at(flat);
  if (!seg.deflection) {
    return *model_.segments()[flat].rest_query;
  }
  // mesh() writes the deformed positions the steps left pending (they are lazy), then the
  // structure built on that mesh refits to them.
  const TriangleMesh& mesh = seg.deflection->mesh();
  if (!seg.deformed_bvh) {
    seg.deformed_bvh = std::make_unique<MeshBvh>(mesh);
  } else if (seg.deformed_dirty) {
    seg.deformed_bvh->refit();
  }
  seg.deformed_dirty = false;
  return *seg.deformed_bvh;
}

const VertexDeflection* World::deflection(std::size_t body, std::size_t segment) const {
  return state_.segments.at(flat_of(model_, body, segment)).deflection.get();
}

double World::current_deflection_m(std::size_t body, std::size_t segment) const {
  if (state_.fem && model_.segments().at(flat_of(model_, body, segment)).fem) {
    const auto& fem_bodies = model_.fem_bodies();
    const auto it = std::find(fem_bodies.begin(), fem_bodies.end(), body);
    return state_.fem->max_displacement_m(static_cast<std::size_t>(it - fem_bodies.begin()));
  }
  const VertexDeflection* d = deflection(body, segment);
  return d != nullptr ? d->max_deflection_m() : 0.0;
}

ContactMaterial World::effective_material(std::uint32_t material, double dt_s) const {
  return hapsim::effective_material(model_, state_.material_contact.at(material), dt_s);
}

namespace {

// haptic path
void forget_motion(ToolRuntime& tool) noexcept {
  tool.has_previous = false;
  // The tool may come back anywhere (as after an unusable input): no side or dent is kept.
  for (PenaltySide& side : tool.penalty_side) {
    side = PenaltySide{};
  }
  std::fill(tool.pressing.begin(), tool.pressing.end(), std::uint8_t{0});
  std::fill(tool.stick_body.begin(), tool.stick_body.end(), StickPoint{});
}

}  // namespace

void World::forget_tool_motion() noexcept {
  for (ToolRuntime& tool : state_.tools) {
    forget_motion(tool);
  }
}

void World::restart_tools() noexcept {
  forget_tool_motion();
  state_.tools_placed = false;  // place_tools resets each proxy at its tool
}

// haptic path
void World::restart_tools(int device) noexcept {
  const std::vector<ToolDescription>& tools = description().tools;
  for (std::size_t t = 0; t < tools.size() && t < state_.tools.size(); ++t) {
    if (tools[t].device == device) {
      forget_motion(state_.tools[t]);
      state_.tools[t].placed = false;
    }
  }
}

// haptic path
void World::set_device_input(int device, const DeviceInput& input) noexcept {
  if (device >= 1 && device < kMaxWorldDevices) {
    state_.other_inputs[static_cast<std::size_t>(device - 1)] = input;
  }
}

// haptic path
void World::set_rendered_push(std::span<const double> push_n) noexcept {
  const std::size_t n = std::min(push_n.size(), state_.rendered_push_n.size());
  std::copy_n(push_n.begin(), n, state_.rendered_push_n.begin());
}

bool World::set_material_contact(std::uint32_t material, const ContactMaterial& c) noexcept {
  const auto positive = [](double v) { return std::isfinite(v) && v > 0.0; };
  const auto non_negative = [](double v) { return std::isfinite(v) && v >= 0.0; };
  if (material >= state_.material_contact.size() || !positive(c.stiffness_n_per_m) ||
      !positive(c.max_penetration_m) || !positive(c.max_force_n) ||
      !non_negative(c.damping_n_s_per_m) || !non_negative(c.static_friction) ||
      !non_negative(c.dynamic_friction) || c.dynamic_friction > c.static_friction) {
    return false;
  }
  // A sheet that a press would not settle on is refused as the loader refuses it.
  const ContactMaterial before = state_.material_contact[material];
  state_.material_contact[material] = c;
  if (!model_.sheet_presses_settle(state_.material_contact)) {
    state_.material_contact[material] = before;
    return false;
  }
  state_.materials_dt_s = -1.0;  // the next step recomputes the effective materials
  return true;
}

std::string World::content_hash() const {
  return hapsim::content_hash(description());
}

std::size_t World::query_memory_bytes() const {
  return model_.query_memory_bytes();
}

}  // namespace hapsim
