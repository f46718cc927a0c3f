// The per-step half of a world (MuJoCo's mjData): everything a step reads and writes, sized once
// from a WorldModel so that step() allocates nothing. Each field says which stage of the step
// (world_stages.h) fills it. The model (world_model.h) is never written by a step.
#pragma once

#include "hapsim/collision/sphere_tree.h"
#include "hapsim/core/device_io.h"
#include "hapsim/core/types.h"
#include "hapsim/deform/vertex_deflection.h"
#include "hapsim/deform/virtual_sheet.h"
#include "hapsim/force/contact_friction.h"
#include "hapsim/force/contact_material.h"
#include "hapsim/force/god_object.h"
#include "hapsim/force/local_contact_model.h"
#include "hapsim/world/indices.h"
#include "hapsim/world/world_description.h"
#include "hapsim/world/world_model.h"

#include <array>
#include <cstdint>
#include <memory>
#include <span>
#include <vector>

namespace hapsim {

class MeshBvh;
class FemCoupling;

/// One contact of one tool with one segment this step.
struct WorldContact {
  ToolIndex tool = kNoTool;
  BodyIndex body = kNoBody;
  LocalSegment segment = kNoSegment;  ///< within the body (not flat)
  Vec3 point_world = Vec3::Zero();
  Vec3 normal_world = Vec3::Zero();  ///< unit, out of the segment towards the tool
  double depth_m = 0.0;              ///< tool depth below the rest surface (≥ 0)
  double force_n = 0.0;              ///< magnitude of this contact's force on the tool
  bool proxy = false;                ///< answered by the god-object (else penalty)
};

/// One contact of a dynamic body with another body's segment this step (body contacts stage):
/// the force on the dynamic body; the other body gets the opposite.
struct BodyContact {
  BodyIndex body = kNoBody;                 ///< the dynamic body
  BodyIndex other_body = kNoBody;           ///< the body it touches
  LocalSegment other_segment = kNoSegment;  ///< within other_body (not flat)
  Vec3 point_world = Vec3::Zero();          ///< on the other body's surface
  Vec3 normal_world = Vec3::Zero();         ///< unit, out of the other body towards the dynamic one
  double depth_m = 0.0;
  Vec3 force_world_n = Vec3::Zero();  ///< on the dynamic body (normal and friction)
};

/// Where a body is and how it moves (every body; only dynamic ones change, integrate stage).
struct BodyState {
  bool dynamic = false;
  Iso3 X_world_body = Iso3::Identity();
  Iso3 X_body_world = Iso3::Identity();
  /// Dynamic bodies: the centre of mass's velocity and the angular velocity, world frame.
  Vec3 v_world = Vec3::Zero();
  Vec3 w_world = Vec3::Zero();
  /// Sums of this step's contact forces on the body and their torques about its centre of mass
  /// (respond and body-contact stages), world frame.
  Vec3 force_world_n = Vec3::Zero();
  Vec3 torque_world_nm = Vec3::Zero();
  /// This step's contact springs and dampers on the body, linearised about its centre of mass in
  /// its generalised velocity [v_world; ω_world] (dynamic bodies only): what lets the integrate
  /// stage treat them implicitly, so that stiff contacts on a light or small body stay stable.
  Eigen::Matrix<double, 6, 6> stiffness_6 = Eigen::Matrix<double, 6, 6>::Zero();
  Eigen::Matrix<double, 6, 6> damping_6 = Eigen::Matrix<double, 6, 6>::Zero();
  /// Σ Jᵀ·S·v_anchor: the springs' other ends move (a tool, a pad, another body), so a spring
  /// stretches by dt·(v_point − v_anchor), not dt·v_point.
  Eigen::Matrix<double, 6, 1> anchor_6 = Eigen::Matrix<double, 6, 1>::Zero();
  /// Integrate stage scratch: the implicit velocity system (and its inverse, only when the body
  /// touches another dynamic body), right-hand side and solution this step, and whether the body
  /// took the implicit path.
  Eigen::Matrix<double, 6, 6> system_6 = Eigen::Matrix<double, 6, 6>::Identity();
  Eigen::Matrix<double, 6, 6> inverse_6 = Eigen::Matrix<double, 6, 6>::Identity();
  Eigen::Matrix<double, 6, 1> rhs_6 = Eigen::Matrix<double, 6, 1>::Zero();
  Eigen::Matrix<double, 6, 1> dv_6 = Eigen::Matrix<double, 6, 1>::Zero();
  bool implicit = false;
  /// The centre of mass, world frame.
  [[nodiscard]] Vec3 com_world(const Vec3& com_body) const { return X_world_body * com_body; }
  /// Adds a spring of stiffness matrix S and damper D (world frame, N/m and N·s/m) acting at
  /// `p_world`, whose other end moves at `v_anchor_world`, to stiffness_6 / damping_6 / anchor_6
  /// (no-op for a body that does not move). haptic path
  void add_contact_spring(const Vec3& p_world, const Vec3& com_body, const Mat3& S, const Mat3& D,
                          const Vec3& v_anchor_world) noexcept;
  /// Velocity of the body's material point at `p_world`.
  [[nodiscard]] Vec3 velocity_at(const Vec3& p_world, const Vec3& com_body) const {
    return v_world + w_world.cross(p_world - com_world(com_body));
  }
};

/// Overlapping leaf pairs one dynamic mesh and one other segment may have in one step; beyond it
/// the pair's contacts are partial and WorldState::dropped_body_contacts counts it.
inline constexpr std::size_t kMaxBodyLeafPairs = 16384;

/// The springs and dampers between two dynamic bodies i and j this step, as they enter body i's
/// equation: ∂F_i/∂x_j and ∂F_i/∂v_j in generalised coordinates (the integrate stage solves
/// touching bodies together, not each against the other's old velocity).
struct BodyCoupling {
  Eigen::Matrix<double, 6, 6> stiffness_6 = Eigen::Matrix<double, 6, 6>::Zero();
  Eigen::Matrix<double, 6, 6> damping_6 = Eigen::Matrix<double, 6, 6>::Zero();
  bool active = false;
};

/// Per (dynamic segment, flat segment) pair: what the body-contact stage remembers between steps.
struct BodyPairState {
  QueryHint hint;         ///< the other segment's query
  QueryHint hint_own;     ///< the dynamic segment's own query (a mesh's: the other's vertices)
  StickPoint stick_body;  ///< friction stick point, in the other segment's body frame
  /// A dynamic mesh: its material point that friction holds there, in its own body frame.
  Vec3 stick_own_body = Vec3::Zero();
  bool touching = false;
};

struct ToolState {
  Vec3 p_world = Vec3::Zero();      ///< the tool's centre, where the device puts it
  Vec3 proxy_world = Vec3::Zero();  ///< god-object position (equals p_world when free)
  Vec3 force_world_n = Vec3::Zero();
  std::int32_t contact_count = 0;
  /// False while the tool is not in the world: another user's tool whose device host has not
  /// joined or went silent (it has no pose; viewers leave it out). Device 0's tools are always
  /// present (an unusable input holds them where they were).
  bool present = true;
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
  /// segment), and proxies that let go of a surface with the device inside that body (a lost
  /// bone): must stay 0.
  std::int32_t penalty_pop_throughs = 0;
  /// Contacts of dynamic bodies with other bodies this step.
  std::span<const BodyContact> body_contacts;
  /// Every body's pose and motion after this step (dynamic bodies move).
  std::span<const BodyState> bodies;
  /// Per sheet (in flat segment order): its deepest dent below rest after this step.
  std::span<const double> sheet_depth_m;
  /// Body contacts found but not reported because the per-step buffer was full.
  std::int32_t dropped_body_contacts = 0;
  /// The world's controller (WorldDescription::controller), which has observed this result, or
  /// null when the world has none: its own reports are read through it (rig/rig_controller.h).
  const ControllerState* controller = nullptr;
};

/// Which side of a penalty segment a tool is pressing from. A penalty contact's depth is measured
/// to the nearest rest surface; inside a thin segment (a 2 mm plate, a membrane) the nearest
/// surface becomes the far one once the tool passes the middle, and the spring would then pull the
/// tool through. So a contact remembers the side it is on: the normal and surface point of its
/// last step on that side; a normal that flips within one step (more than 90°: no sliding over a
/// curved surface turns it that far in a millisecond) means the tool crossed the middle, and from
/// then on the force stays along the remembered normal, with the depth below the remembered
/// tangent plane. Leaving the segment while crossed is leaving through the far side: a
/// pop-through.
struct PenaltySide {
  Vec3 n_world = Vec3::Zero();      ///< unit, out of the segment on the entry side
  Vec3 point_world = Vec3::Zero();  ///< surface point on the entry side
  bool in_contact = false;
  bool crossed = false;  ///< the nearest surface is now the far one
};

/// A penalty contact found by the detection stage, answered by the response stage.
struct PenaltyCandidate {
  FlatSegment segment{0};  ///< flat (not within its body)
  /// Below the surface the tool feels: the rest surface, less the dent other contacts left there.
  double depth_m = 0.0;
  /// Below the rest surface: how far this contact itself deflects the surface (eq. 1's x).
  double rest_depth_m = 0.0;
  Vec3 n_world = Vec3::Zero();
  Vec3 point_world = Vec3::Zero();      ///< on the surface the tool feels
  Vec3 rest_point_body = Vec3::Zero();  ///< the contact point on the rest surface, body frame
};

/// The dent a tool's contact made on a segment last step (eq. 1 about its rest point): what the
/// other tools feel of it.
struct OwnDent {
  Vec3 p_body = Vec3::Zero();
  double penetration_m = 0.0;
  double contact_radius_m = 0.0;
  std::uint64_t step = 0;  ///< WorldState::step_index of the step that made it (0: none)
};

/// Per-step state of one deformable segment.
struct SegmentState {
  std::unique_ptr<VertexDeflection> deflection;  ///< deformable bodies only (deform stage)
  std::unique_ptr<MeshBvh> deformed_bvh;         ///< built on first World::deformed_query()
  bool deformed_dirty = false;                   ///< deform stage: vertices moved
  /// This step's contacts on the segment (respond stage), capacity fixed at construction.
  std::vector<DeflectionContact> pending;
  std::size_t pending_count = 0;
  /// A Gaussian sheet (BodyDeformation::kGaussianSheet): its grid, the query over its elastic
  /// field that contacts use, and this step's pushes on it (respond and body-contact stages;
  /// the deform stage applies them).
  std::unique_ptr<VirtualSheet> sheet;
  std::unique_ptr<ProximityQuery> sheet_query;
  std::vector<SheetContact> sheet_pushes;
  std::size_t sheet_push_count = 0;
  /// The sheet's mesh changed this step (deform stage).
  bool sheet_dirty = false;
  /// Body-contact stage, worlds with dynamic meshes: per rest-mesh vertex, the pass that last
  /// tried it (each vertex is tried once per pair however many leaf pairs hold it).
  std::vector<std::uint32_t> vertex_pass;
};

/// One tool against one FEM body (fem_coupling.h): the local contact model the FEM side handed
/// the haptic path (adopted before the step), and the force the step rendered from it.
struct FemToolContact {
  LocalContactModel model;
  /// The model `model` replaced at the last adoption, and whether that adoption is still to be
  /// blended in (set by FemCoupling::adopt, read by the FEM contacts stage).
  LocalContactModel previous_model;
  bool adopted_this_step = false;
  /// The blend: at an adoption, what the old model (and what was left of its blend) rendered at
  /// the tool minus what the new one renders there; it decays linearly to zero over one FEM
  /// period from `blend_from_step`, so a new model is felt as a ramp, not a step (as a device
  /// host blends a served model: device/local_model_renderer.h).
  Vec3 blend_offset_n = Vec3::Zero();
  std::uint64_t blend_from_step = 0;
  /// Respond stage: this step's force on the tool from the body, world frame (the FEM's load).
  Vec3 push_world_n = Vec3::Zero();
};

/// Per-step state of one tool.
struct ToolRuntime {
  GodObject proxy;                           ///< respond stage
  std::vector<ProxySurface> surfaces;        ///< one per proxy segment
  std::vector<std::size_t> surface_segment;  ///< flat segment of each surface
  /// The surface (index into `surfaces`) the proxy touched last step, -1 for none: a proxy that
  /// lets go of it while the device is inside that body has lost it (counted as a pop-through).
  int proxy_surface_last_step = -1;
  std::vector<QueryHint> hints;  ///< per flat segment (temporal coherence)
  /// Per flat segment: the tool was within reach of, or inside, it last step. Only then can it be
  /// deeper than the reach now (it moves far less than a reach per cycle), so only then is the
  /// costly deep-inside query needed (detect stage).
  std::vector<std::uint8_t> near_last_step;
  std::vector<PenaltySide> penalty_side;  ///< per flat segment (detect stage)
  std::vector<OwnDent> own_dent;          ///< per flat segment (respond stage)
  /// Per flat segment: how deep the surface under the tool is dented by others — other tools'
  /// presses, or an earlier press still recovering (detect stage). Found when the tool starts
  /// pressing (the deformed surface there), then it follows the other tools' dents and recovers
  /// at the tissue's rate, never jumping; the tool's own press is its spring and does not count.
  std::vector<double> felt_dent_m;
  std::vector<std::uint8_t> pressing;  ///< per flat segment: in contact last step
  /// Per flat segment: where a penalty contact with friction sticks, in the segment's body frame
  /// (respond stage).
  std::vector<StickPoint> stick_body;
  /// Penalty contacts of this step, in segment order (detect stage); capacity = penalty segments.
  std::vector<PenaltyCandidate> penalty;
  std::size_t penalty_count = 0;
  Vec3 p_world = Vec3::Zero();  ///< place stage: where the device puts the tool this step
  Vec3 v_world = Vec3::Zero();  ///< place stage: finite-difference velocity (zero after a jump)
  double moved_m = kInf;        ///< place stage: distance since last step (inf: no last step)
  Vec3 p_previous_world = Vec3::Zero();
  double input_time_previous_s = 0.0;  ///< the device input's own time stamp last step
  /// Place stage: the input of the tool's device was usable (healthy, finite) this step.
  bool input_usable = false;
  /// The proxy was placed at the tool once since the tool's device (re)started.
  bool placed = false;
  bool has_previous = false;
};

struct WorldState {
  /// Sizes every buffer for `model` and builds the deformation state of deformable segments.
  /// Throws hapsim::Error naming the segment when its deformation cannot be built.
  explicit WorldState(const WorldModel& model);
  ~WorldState();
  WorldState(const WorldState&) = delete;
  WorldState& operator=(const WorldState&) = delete;

  /// Back to rest: tools re-placed at the next input, deformation and hints cleared.
  void reset();

  /// Materials as edited live (World::set_material_contact); start as the description's.
  std::vector<ContactMaterial> material_contact;
  /// Effective materials (stiffness clamped, passivity damping floor) for `materials_dt_s`.
  std::vector<ContactMaterial> materials;
  /// The same for contacts between bodies (body-contact stage): the passivity floor without the
  /// device's stiffness clamp (no device renders them).
  std::vector<ContactMaterial> body_materials;
  double materials_dt_s = -1.0;

  std::vector<SegmentState> segments;  ///< per flat segment
  std::vector<ToolRuntime> tools;
  std::vector<BodyState> bodies;  ///< per body
  /// Per (dynamic segment i of model.dynamic_segments(), flat segment s): [i · segments + s].
  std::vector<BodyPairState> body_pairs;
  /// Body-contact stage scratch for dynamic meshes: overlapping leaves (capacity fixed at
  /// construction; a pair with more counts in dropped_body_contacts, its contacts partial) and
  /// the pass number behind SegmentState::vertex_pass.
  std::vector<LeafPair> leaf_pairs;
  std::uint32_t vertex_pass = 0;
  /// Per ordered pair of dynamic bodies (i, j) by their model.dynamic_bodies() indices: [i·n + j].
  std::vector<BodyCoupling> couplings;
  /// Adds a spring S and damper D (world frame) between the dynamic bodies' points p_a_world (on
  /// body a) and p_b_world (on body b) to both bodies' couplings; no-op unless both are dynamic.
  /// haptic path
  void couple_bodies(const WorldModel& model, std::size_t body_a, std::size_t body_b,
                     const Vec3& p_a_world, const Vec3& p_b_world, const Mat3& S,
                     const Mat3& D) noexcept;
  /// The same for a rotational damper D between the two bodies' angular velocities. haptic path
  void couple_rotations(const WorldModel& model, std::size_t body_a, std::size_t body_b,
                        const Mat3& D) noexcept;
  /// Body contacts stage: this step's contacts of dynamic bodies, capacity fixed at construction.
  std::vector<BodyContact> body_contacts;
  std::size_t body_contact_count = 0;
  /// Deform stage: per sheet (in flat segment order), its deepest dent below rest.
  std::vector<double> sheet_depth_m;
  /// The description's controller's state (world_controller.h), or null.
  std::unique_ptr<ControllerState> controller;
  /// Per (tool t, FEM body b): [t · kMaxFemBodies + b] (world/fem_coupling.h); empty without FEM
  /// bodies.
  std::vector<FemToolContact> fem_contacts;
  /// The FEM bodies and their coupling to the cycle (null without FEM bodies). The step adopts
  /// and launches; FemCoupling::run_pending() runs on the FEM side (World::advance_fem).
  std::unique_ptr<FemCoupling> fem;
  /// False: the step itself runs each FEM update right after launching it (tests, replays:
  /// deterministic, costly steps). True: someone else calls World::advance_fem() (an inline
  /// session between cycles, or the FEM thread in real time).
  bool fem_deferred = false;
  /// Updates the step ran itself that failed (an exception from the solver), counted.
  std::uint64_t fem_failures = 0;
  double time_s = 0.0;
  /// Steps taken since construction or reset (the first step is 1).
  std::uint64_t step_index = 0;
  /// Place stage: the step's own input (device 0) was usable (healthy, finite) this step.
  bool input_usable = false;
  /// The inputs of the other users' devices (index k - 1 for device k; World::set_device_input),
  /// unhealthy until one is given.
  std::array<DeviceInput, kMaxWorldDevices - 1> other_inputs = [] {
    std::array<DeviceInput, kMaxWorldDevices - 1> unheard{};
    for (DeviceInput& input : unheard) {
      input.healthy = false;
    }
    return unheard;
  }();
  /// The proxies have been placed at a first position (reset() clears it).
  bool tools_placed = false;
  /// Place stage: the glove hand's tracker pose and finger angles from the last usable input
  /// (a world with a hand; what a display draws the hand from).
  GloveReading hand;

  // Outputs of the step (respond and safety stages).
  std::vector<ToolState> tool_states;
  /// Per tool, the push its device rendered (World::set_rendered_push), for this step's sheet
  /// pushes; NaN: not known. Cleared to NaN after each step.
  std::vector<double> rendered_push_n;
  std::vector<WorldContact> contacts;  ///< capacity fixed at construction
  std::size_t contact_count = 0;
  std::int32_t dropped_contacts = 0;
  std::int32_t dropped_body_contacts = 0;
  std::int32_t pop_throughs = 0;
  DeviceCommand command;
  StepResult result;

  /// Where segment `seg` (flat) is now: its body's current pose.
  [[nodiscard]] const Iso3& X_world_body(const SegmentModel& seg) const {
    return bodies[seg.body].X_world_body;
  }
  [[nodiscard]] const Iso3& X_body_world(const SegmentModel& seg) const {
    return bodies[seg.body].X_body_world;
  }
  /// The query a step uses for a segment: a sheet's live field, else the rest surface's.
  [[nodiscard]] const ProximityQuery& contact_query(const SegmentModel& seg,
                                                    std::size_t flat) const {
    return segments[flat].sheet_query ? *segments[flat].sheet_query : *seg.rest_query;
  }

 private:
  const WorldModel* model_ = nullptr;  // the model this state was sized for (reset)
};

}  // namespace hapsim
