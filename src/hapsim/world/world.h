// The simulated world and its deterministic step (SPEC §3, §4, §7): device input in, per-tool
// forces, contacts and deformation out.
//
// Built once from a WorldDescription (read-only afterwards); step() only touches per-step state
// that was sized at construction, so it allocates nothing (haptic path) and is a pure function
// of the state and the input: the same inputs replay to the same bits.
//
// One step, per tool (a sphere at the device pose times its offset):
//  1. proxy segments (bone, ligament, sheet): the tool's god-object proxy moves towards the
//     tool without entering any of them; force = spring from the tool to the proxy;
//  2. penalty segments (skin, muscle): F = k·x along the normal at the tool's own depth x,
//     capped by the segment's maximum penetration and maximum force; a contact remembers the
//     side it entered from, so a thin segment never pulls the tool through (world.cpp);
//  3. normal damping on both, never below the passivity floor factor·k·dt;
//  4. deformable segments deflect under every contact (eq. 1), the rest recover.
// Depths are measured against each segment's rest surface (the tissue's spring), which keeps
// force and deflection consistent: the dent follows the probe instead of pushing it out. The
// deformed surface has its own exact structure, refitted (never rebuilt) on demand.
#pragma once

#include "hapsim/collision/proximity_query.h"
#include "hapsim/core/device_io.h"
#include "hapsim/core/types.h"
#include "hapsim/force/god_object.h"
#include "hapsim/world/world_description.h"

#include <cstdint>
#include <memory>
#include <span>
#include <string>
#include <vector>

namespace hapsim {

class MeshBvh;
class VertexDeflection;
struct PenaltySide;

struct WorldOptions {
  /// Stiffness of every material is clamped to this (the device's rated maximum keeps the
  /// rendering stable on it); infinity: no clamp.
  double max_stiffness_n_per_m = kInf;
  /// God-object parameters (the radius comes from each tool).
  double proxy_max_substep_m = 2.5e-4;
  int proxy_max_iterations = 16;
};

/// One contact of one tool with one segment this step.
struct WorldContact {
  std::int32_t tool = -1;
  std::int32_t body = -1;
  std::int32_t segment = -1;  ///< within the body
  Vec3 point_world = Vec3::Zero();
  Vec3 normal_world = Vec3::Zero();  ///< unit, out of the segment towards the tool
  double depth_m = 0.0;              ///< tool depth below the rest surface (≥ 0)
  double force_n = 0.0;              ///< magnitude of this contact's force on the tool
  bool proxy = false;                ///< answered by the god-object (else penalty)
};

struct ToolState {
  Vec3 p_world = Vec3::Zero();      ///< the tool's centre, where the device puts it
  Vec3 proxy_world = Vec3::Zero();  ///< god-object position (equals p_world when free)
  Vec3 force_world_n = Vec3::Zero();
  std::int32_t contact_count = 0;
};

struct StepResult {
  double time_s = 0.0;
  std::span<const ToolState> tools;
  std::span<const WorldContact> contacts;
  /// Forces for the device (not yet clamped to its rated limits: the safety layer does that).
  DeviceCommand command;
  /// Contacts found but not reported because the per-step buffer was full.
  std::int32_t dropped_contacts = 0;
  /// Tools that left a penalty segment through its far side this step (pulled through a thin
  /// segment: must stay 0).
  std::int32_t penalty_pop_throughs = 0;
};

/// A content hash of a world description (meshes, materials, tools), as recordings carry it.
[[nodiscard]] std::string content_hash(const WorldDescription& description);

class World {
 public:
  /// Builds every query structure and deformation state. Throws hapsim::Error naming the body
  /// or segment on an unusable description (empty mesh, bad material index, too many segments).
  explicit World(WorldDescription description, WorldOptions options = {});
  ~World();
  World(const World&) = delete;
  World& operator=(const World&) = delete;

  /// haptic path. Advances by `dt_s` with this cycle's device input. A non-finite or unhealthy
  /// input holds the tools where they were and outputs zero force (never NaN).
  const StepResult& step(const DeviceInput& input, double dt_s);
  /// Back to rest: tools re-placed at the next input, deformation cleared.
  void reset();
  /// haptic path. New contact parameters for material `material` from the next step on (a user
  /// tuning stiffness and limits live). Only on the thread that steps. Returns false, changing
  /// nothing, for a bad index or values a step cannot use (non-finite, stiffness, limits ≤ 0,
  /// negative damping or friction, dynamic above static friction).
  bool set_material_contact(std::uint32_t material, const ContactMaterial& contact) noexcept;
  /// haptic path. The next step takes the tools' positions as new, with no velocity from where
  /// they were (after a pause, the device may have moved far: no damping spike).
  void forget_tool_motion() noexcept;

  [[nodiscard]] const WorldDescription& description() const { return description_; }
  [[nodiscard]] const StepResult& last_result() const { return result_; }
  [[nodiscard]] std::size_t body_count() const { return description_.bodies.size(); }
  [[nodiscard]] std::size_t segment_count(std::size_t body) const;
  /// Flat index of (body, segment) over all bodies, for per-segment statistics.
  [[nodiscard]] std::size_t flat_segment(std::size_t body, std::size_t segment) const;
  [[nodiscard]] std::size_t flat_segment_count() const { return segments_.size(); }

  /// The rest-shape query of a segment (body frame): the one step() uses.
  [[nodiscard]] const ProximityQuery& rest_query(std::size_t body, std::size_t segment) const;
  /// The segment's current (deformed) surface, body frame.
  [[nodiscard]] const TriangleMesh& surface(std::size_t body, std::size_t segment) const;
  /// Exact query on the current (deformed) surface, refitted if it moved since the last call.
  /// Not on the haptic path (the refit is O(segment size)); for display, picking and checks.
  [[nodiscard]] const ProximityQuery& deformed_query(std::size_t body, std::size_t segment);
  /// The segment's deflection state (rest positions, inward directions, vertices moved by the last
  /// step), or null when the body is not deformable. For publishing the deformation to other
  /// threads: only the thread that steps may read it while the world runs.
  [[nodiscard]] const VertexDeflection* deflection(std::size_t body, std::size_t segment) const;
  /// Largest deflection of a segment right now, metres (0 if not deformable).
  [[nodiscard]] double current_deflection_m(std::size_t body, std::size_t segment) const;
  /// The material a step actually uses (stiffness clamped, damping floor applied for `dt_s`).
  [[nodiscard]] ContactMaterial effective_material(std::uint32_t material, double dt_s) const;

  /// A content hash of the description (meshes, materials, tools), for recordings; the same as
  /// content_hash(description()).
  [[nodiscard]] std::string content_hash() const;
  /// Bytes of all query structures (meshes excluded).
  [[nodiscard]] std::size_t query_memory_bytes() const;
  /// Construction time, milliseconds.
  [[nodiscard]] double build_ms() const { return build_ms_; }

 private:
  struct Segment;
  struct Tool;

  void update_materials(double dt_s);
  void step_tool(std::size_t t, const Vec3& p_world, double dt_s);
  void add_contact(const WorldContact& contact);
  void end_penalty_contact(PenaltySide& side);

  WorldDescription description_;
  std::unique_ptr<HandModel> hand_;  // when a glove drives the tools
  WorldOptions options_;
  std::vector<std::unique_ptr<Segment>> segments_;  // flat over bodies
  std::vector<std::size_t> body_first_segment_;
  std::vector<std::unique_ptr<Tool>> tools_;
  std::vector<ContactMaterial> materials_;  // effective, for materials_dt_s_
  double materials_dt_s_ = -1.0;
  std::vector<ToolState> tool_states_;
  std::vector<WorldContact> contacts_;  // capacity fixed at construction
  std::size_t contact_count_ = 0;
  std::int32_t dropped_contacts_ = 0;
  std::int32_t pop_throughs_ = 0;
  StepResult result_;
  double time_s_ = 0.0;
  bool tools_placed_ = false;
  double build_ms_ = 0.0;
};

}  // namespace hapsim
