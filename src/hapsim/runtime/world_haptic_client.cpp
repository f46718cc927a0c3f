#include "hapsim/runtime/world_haptic_client.h"

#include "hapsim/deform/vertex_deflection.h"
#include "hapsim/deform/virtual_sheet.h"
#include "hapsim/rig/rig_controller.h"
#include "hapsim/runtime/tool_rendered_force.h"

#include <algorithm>
#include <chrono>

namespace hapsim {

namespace {

constexpr std::uint8_t kOwedToAll = 0x7;  // listed for each of the three snapshot slots

}  // namespace

WorldHapticClient::WorldHapticClient(World& world, WorldHapticClientOptions options)
    : world_(world), options_(options) {
  const WorldDescription& d = world_.description();
  if (const TeleopRigDescription* rig = rig_description(d); rig != nullptr) {
    carried_tool_ = rig->carried_tool;
  }
  max_deflection_m_.assign(world_.flat_segment_count(), 0.0);
  for (std::size_t b = 0; b < d.bodies.size(); ++b) {
    if (world_.sheet(b) != nullptr) {
      sheets_.emplace_back(world_.flat_segment(BodyIndex{b}, LocalSegment{0}).index(), b);
    }
    for (std::size_t s = 0; s < d.bodies[b].segments.size(); ++s) {
      const VertexDeflection* deflection = world_.deflection(b, s);
      if (deflection == nullptr) {
        continue;
      }
      DeformableSegment seg;
      seg.flat = world_.flat_segment(BodyIndex{b}, LocalSegment{s}).index();
      seg.deflection = deflection;
      const std::size_t n = deflection->mesh().vertices.size();
      for (std::vector<std::uint32_t>& pending : seg.pending) {
        pending.assign(n, 0);  // capacity n, pages mapped now
        pending.clear();
      }
      seg.owed.assign(n, 0);
      deformable_.push_back(std::move(seg));
    }
  }
  if (options_.publish_snapshots) {
    snapshots_ = std::make_unique<TripleBuffer<WorldSnapshot>>(make_world_snapshot(world_));
  }
  if (options_.record_capacity > 0) {
    records_ = std::make_unique<SpscRing<CycleRecord>>(options_.record_capacity);
  }
  zero_command_.finger_count = 0;
}

// haptic path
const DeviceCommand& WorldHapticClient::step(const DeviceInput& input, double dt_s) {
  if (reset_requested_.exchange(false, std::memory_order_acquire)) {
    world_.reset();
    soft_start_ = true;
    // Every vertex may have moved back to rest (a rare O(vertices) cycle, asked for by a user).
    for (DeformableSegment& seg : deformable_) {
      for (std::vector<std::uint32_t>& pending : seg.pending) {
        pending.clear();
        for (std::uint32_t v = 0; v < seg.owed.size(); ++v) {
          pending.push_back(v);
        }
      }
      std::fill(seg.owed.begin(), seg.owed.end(), kOwedToAll);
      ++seg.changes;
    }
  }
  while (const MaterialChange* change = material_changes_.front()) {
    if (!world_.set_material_contact(change->material, change->contact)) {
      refused_material_changes_.store(refused_material_changes_.load(std::memory_order_relaxed) + 1,
                                      std::memory_order_relaxed);
    }
    material_changes_.pop();
  }
  stepped_ = false;
  const bool paused = paused_.load(std::memory_order_relaxed);
  if (paused != was_paused_) {
    was_paused_ = paused;
    if (!paused) {
      // Back from a pause: the device may have moved far meanwhile. No velocity from the old
      // position (no damping spike), and the force comes back gradually.
      world_.forget_tool_motion();
      soft_start_ = true;
    }
  }
  if (paused) {
    last_result_ = &world_.last_result();
    return zero_command_;
  }
  if (options_.observer != nullptr) {
    options_.observer->before_step(world_);
  }
  const auto t0 = std::chrono::steady_clock::now();
  last_result_ = &world_.step(input, dt_s);
  step_cost_us_ =
      std::chrono::duration<double, std::micro>(std::chrono::steady_clock::now() - t0).count();
  stepped_ = true;
  return last_result_->command;
}

// haptic path
void WorldHapticClient::after_cycle(const HapticCycle& cycle) noexcept {
  // Every vertex that moved this step is owed to each of the three snapshot slots.
  for (DeformableSegment& seg : deformable_) {
    // moved_vertices() is the last step's: nothing new moved in a cycle that did not step.
    const auto moved =
        stepped_ ? seg.deflection->moved_vertices() : std::span<const std::uint32_t>{};
    seg.changes += moved.empty() ? 0 : 1;
    for (const std::uint32_t v : moved) {
      std::uint8_t& owed = seg.owed[v];
      if (owed == kOwedToAll) {
        continue;
      }
      // Listed once per slot (capacity = vertex count: never reallocates).
      for (std::size_t k = 0; k < 3; ++k) {
        if ((owed & (1u << k)) == 0) {
          seg.pending[k].push_back(v);
        }
      }
      owed = kOwedToAll;
    }
    double& peak = max_deflection_m_[seg.flat];
    peak = std::max(peak, seg.deflection->max_deflection_m());
  }
  for (const std::size_t body : world_.model().fem_bodies()) {
    // A FEM body's surface moves on the FEM thread: its newest update's largest displacement.
    double& peak = max_deflection_m_[world_.flat_segment(BodyIndex{body}, LocalSegment{0}).index()];
    peak = std::max(peak, world_.current_deflection_m(body, 0));
  }
  if (snapshots_) {
    publish_snapshot(cycle);
  }
  if (options_.observer != nullptr) {
    if (stepped_) {
      options_.observer->after_step(world_, cycle);
    } else {
      options_.observer->after_paused_cycle(world_, cycle);
    }
  }
  // Records of stepped cycles only, numbered by them (a paused cycle changed nothing: a replay
  // numbers the steps it takes 0, 1, 2, ...).
  if (records_ && stepped_ && last_result_ != nullptr) {
    fill_cycle_record(scratch_record_, recorded_cycles_++, *cycle.input, *last_result_,
                      *cycle.output, step_cost_us_);
    if (!records_->push(scratch_record_)) {
      dropped_records_.store(dropped_records_.load(std::memory_order_relaxed) + 1,
                             std::memory_order_relaxed);
    }
  }
}

// haptic path
void WorldHapticClient::publish_snapshot(const HapticCycle& cycle) noexcept {
  WorldSnapshot& s = snapshots_->write_slot();
  const auto slot = static_cast<std::size_t>(snapshots_->write_index());
  s.cycle = cycle.index;
  s.time_s = cycle.time_s;
  s.world_time_s = world_.state().time_s;
  s.input = *cycle.input;
  s.output = *cycle.output;
  s.hand = world_.hand_reading();
  const WorldDescription& d = world_.description();
  if (last_result_ != nullptr) {
    const StepResult& r = *last_result_;
    const std::size_t tools = std::min(r.tools.size(), s.tools.size());
    std::copy_n(r.tools.begin(), tools, s.tools.begin());
    const std::size_t contacts = std::min(r.contacts.size(), s.contacts.size());
    std::copy_n(r.contacts.begin(), contacts, s.contacts.begin());
    s.contact_count = contacts;
    // The force each tool renders: its finger actuator, or its share of the (clamped) tip force.
    const double tip_n = r.command.force_world_n.norm();
    const double tip_scale = tip_n > 0.0 ? cycle.output->force_world_n.norm() / tip_n : 0.0;
    for (std::size_t t = 0; t < tools; ++t) {
      s.tool_force_n[t] = tool_rendered_force_n(d.tools[t], r.tools[t], *cycle.output, tip_scale,
                                                t == carried_tool_);
    }
  }
  if (s.teleop && rig_state(world_) != nullptr) {
    TeleopSnapshot& t = *s.teleop;
    t.cycle = s.cycle;
    t.time_s = s.time_s;
    t.input = s.input;
    t.output = s.output;
    fill_teleop_snapshot(t, world_);
  }
  for (const std::size_t body : world_.model().fem_bodies()) {
    s.deflection_m[world_.flat_segment(BodyIndex{body}, LocalSegment{0}).index()] =
        world_.current_deflection_m(body, 0);
  }
  for (DeformableSegment& seg : deformable_) {
    std::vector<std::uint32_t>& pending = seg.pending[slot];
    const auto not_owed = static_cast<std::uint8_t>(~(1u << slot));
    s.deflection_m[seg.flat] = seg.deflection->max_deflection_m();
    if (pending.empty()) {
      continue;
    }
    // Each pending vertex's position from its offset (what mesh() would write, without
    // writing the whole segment's pending positions there every cycle).
    const VertexDeflection& deflection = *seg.deflection;
    float* xyz = s.positions_body[seg.flat].data();
    for (const std::uint32_t v : pending) {
      const Vec3 p = deflection.position(v);
      xyz[3 * v + 0] = static_cast<float>(p.x());
      xyz[3 * v + 1] = static_cast<float>(p.y());
      xyz[3 * v + 2] = static_cast<float>(p.z());
      seg.owed[v] &= not_owed;
    }
    pending.clear();
    s.positions_version[seg.flat] = seg.changes;
  }
  // Moving bodies and sheets: a pose per body and a few hundred grid nodes per sheet.
  for (std::size_t b = 0; b < s.body_poses_world.size(); ++b) {
    s.body_poses_world[b] = world_.body_pose(b);
  }
  ++sheet_version_;
  for (const auto& [flat, body] : sheets_) {
    const std::vector<Vec3>& vertices = world_.sheet(body)->mesh().vertices;
    float* xyz = s.positions_body[flat].data();
    for (std::size_t v = 0; v < vertices.size(); ++v) {
      xyz[3 * v + 0] = static_cast<float>(vertices[v].x());
      xyz[3 * v + 1] = static_cast<float>(vertices[v].y());
      xyz[3 * v + 2] = static_cast<float>(vertices[v].z());
    }
    s.positions_version[flat] = sheet_version_;
  }
  snapshots_->publish();
}

}  // namespace hapsim
