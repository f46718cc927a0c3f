// The simulated world (architecture.md#force-and-safety, architecture.md#deformation,
// architecture.md#real-time): device input in, per-tool forces, contacts and deformation out. A
// World holds the read-only model (world_model.h, built once from a WorldDescription) and the
// per-step state (world_state.h, sized at construction), and steps them with the deterministic,
// allocation-free step() of world_step.h: the same inputs replay to the same bits. The stages of a
// step are listed in world_stages.h (place tools, detect contacts, body contacts, respond,
// integrate, deform, safety) and drawn in architecture.md#one-haptic-cycle-1-ms.
// Depths are measured against each segment's rest surface (the tissue's spring), which keeps
// force and deflection consistent: the dent follows the probe instead of pushing it out. The
// deformed surface has its own exact structure, refitted (never rebuilt) on demand.
#pragma once

#include "hapsim/collision/proximity_query.h"
#include "hapsim/core/device_io.h"
#include "hapsim/core/stopwatch.h"
#include "hapsim/core/types.h"
#include "hapsim/world/indices.h"
#include "hapsim/world/world_description.h"
#include "hapsim/world/world_model.h"
#include "hapsim/world/world_state.h"

#include <cstdint>
#include <span>
#include <string>

namespace hapsim {

class FemCoupling;
class VertexDeflection;
class VirtualSheet;

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
  /// negative damping or friction, dynamic above static friction) or that a press on a sheet
  /// would not settle with (WorldModel::sheet_presses_settle).
  bool set_material_contact(std::uint32_t material, const ContactMaterial& contact) noexcept;
  /// haptic path. The next step takes the tools' positions as new, with no velocity from where
  /// they were (after a pause, the device may have moved far: no damping spike).
  void forget_tool_motion() noexcept;
  /// haptic path. The next step's tool positions are a new start, as at the first step: the
  /// device's source changed (a device host took over from the scene's script, or let go), so
  /// the tools land anywhere. Their proxies are placed where the devices now are, not dragged
  /// there from their old contacts across whatever lies between; no motion, side or dent is kept.
  void restart_tools() noexcept;
  /// haptic path. restart_tools() for the tools of device `device` alone (another user's device
  /// joined or left; the others keep their contacts).
  void restart_tools(int device) noexcept;
  /// haptic path. Device `device`'s input for the next steps (1 ≤ device < kMaxWorldDevices: the
  /// tools of another user, ToolDescription::device; device 0's input is step()'s). An unhealthy
  /// or non-finite one holds those tools with no force, as step() does for its own. Out of range:
  /// ignored.
  void set_device_input(int device, const DeviceInput& input) noexcept;
  /// haptic path. SPEC §8, for the next step only: the push each tool's device actually rendered
  /// (N, one per tool; NaN or a missing entry: not known). A sheet a tool presses takes that
  /// push instead of the step's own force: when the device is on another host rendering a local
  /// model, the tissue must give way to what the hand felt, or the model's error over the delay
  /// comes back through the tissue. Entries beyond the tool count are ignored.
  void set_rendered_push(std::span<const double> push_n) noexcept;

  /// FEM bodies (world/fem_coupling.h): by default each step runs the FEM update it launches
  /// (deterministic, and the step pays for it). Deferred, the step only launches and adopts, and
  /// whoever drives the FEM calls advance_fem(): an inline session between cycles (the same
  /// updates at the same steps: the same bits), or the FEM thread in real time.
  void set_fem_deferred(bool deferred) noexcept;
  /// Runs the newest launched FEM update not yet run; false when there was none (or no FEM
  /// body). Only one thread may call it; it may run beside the stepping thread.
  bool advance_fem();
  /// The FEM bodies' coupling, or null when the world has none.
  [[nodiscard]] FemCoupling* fem() { return state_.fem.get(); }
  [[nodiscard]] const FemCoupling* fem() const { return state_.fem.get(); }

  /// The description the world was built from (materials as described: live edits are in
  /// material_contact()).
  [[nodiscard]] const WorldDescription& description() const { return model_.description(); }
  [[nodiscard]] const WorldModel& model() const { return model_; }
  /// The per-step state: only the thread that steps may read it while the world runs.
  [[nodiscard]] const WorldState& state() const { return state_; }
  [[nodiscard]] const StepResult& last_result() const { return state_.result; }
  /// A material's contact parameters as edited live (set_material_contact), before the clamp.
  [[nodiscard]] const ContactMaterial& material_contact(std::uint32_t material) const {
    return state_.material_contact.at(material);
  }
  [[nodiscard]] std::size_t body_count() const { return description().bodies.size(); }
  /// The state of the description's controller (a robot's rig: rig/rig_controller.h), or null
  /// when the world has none. Only the thread that steps may read it while the world runs.
  [[nodiscard]] const ControllerState* controller() const { return state_.controller.get(); }
  /// The glove hand's pose and finger angles from the last usable input (a world with a hand;
  /// the tools sit at its fingertips). Only the thread that steps may read it while it runs.
  [[nodiscard]] const GloveReading& hand_reading() const { return state_.hand; }
  [[nodiscard]] std::size_t segment_count(std::size_t body) const;
  /// Where a body is now (a dynamic body moves; the others stay at their description's pose).
  /// Only the thread that steps may read it while the world runs.
  [[nodiscard]] const Iso3& body_pose(std::size_t body) const {
    return state_.bodies.at(body).X_world_body;
  }
  /// The virtual sheet of a sheet body (BodyDeformation::kGaussianSheet), or null.
  [[nodiscard]] const VirtualSheet* sheet(std::size_t body) const;
  /// Flat index of (body, body-local segment) over all bodies, for per-segment statistics and
  /// the per-flat-segment arrays (WorldSnapshot, WorldModel::segments()).
  [[nodiscard]] FlatSegment flat_segment(BodyIndex body, LocalSegment segment) const;
  [[nodiscard]] std::size_t flat_segment_count() const { return model_.segments().size(); }

  /// The rest-shape query of a segment (body frame): the one step() uses.
  [[nodiscard]] const ProximityQuery& rest_query(std::size_t body, std::size_t segment) const;
  /// The segment's current (deformed) surface, body frame. For a deformable segment this writes
  /// the positions the steps left pending (they are display data, written lazily: see
  /// VertexDeflection::mesh()), so only on the thread that steps, or while nothing steps.
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
  /// Construction time (model and state), milliseconds.
  [[nodiscard]] double build_ms() const { return build_ms_; }

 private:
  Stopwatch build_watch_;  // first member: started before the model and the state are built
  WorldModel model_;
  WorldState state_;
  double build_ms_ = 0.0;
};

}  // namespace hapsim
