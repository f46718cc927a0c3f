// Multirate coupling of FEM bodies to the 1 kHz cycle (architecture.md#deformation, SPEC §12).
//
// The FEM never runs in the haptic cycle. Every `period_steps` steps the haptic path *launches*
// an update: it copies what the FEM needs (each tool's position and velocity, the force each tool
// felt from each FEM body: what the device rendered) into a fixed-size FemLaunch. The FEM side
// (its own thread in real time, or the stepping thread between cycles in an inline run) takes
// the newest launch: loads each body with the rendered forces on the tool's contact patch, steps
// it, and builds per (tool, body) a *local contact model* (force/local_contact_model.h, the type
// the network carries): the deformed surface's closest point and normal, f0 at the tool's x0, and
// the stiffness of the contact spring in series with the tissue's own compliance there
// (nᵀ·H·K⁻¹·Hᵀ·n over the patch: Duriez et al. 2006). The haptic path *adopts* an update exactly
// `period_steps` steps after its launch (a fixed latency of one FEM period), or, in real time,
// at the first step after that when it is ready (a late update, counted), and renders the
// models from the tool's fresh position every cycle (stage_fem_contacts.cpp).
//
// Determinism: an update depends only on its launch's data and the FEM's state, and updates
// run one after another in launch order; with adoption at launch + period_steps the whole run is
// a function of the device inputs, so recordings replay bit for bit. A late update in real time
// changes that; the summary counts late updates (none in an inline run).
#pragma once

#include "hapsim/core/triple_buffer.h"
#include "hapsim/core/types.h"
#include "hapsim/deform/fem_body.h"
#include "hapsim/force/local_contact_model.h"
#include "hapsim/geometry/tet_embedding.h"
#include "hapsim/geometry/triangle_mesh.h"
#include "hapsim/world/world_description.h"

#include <array>
#include <atomic>
#include <cstddef>
#include <cstdint>
#include <memory>
#include <vector>

namespace hapsim {

class WorldModel;
struct WorldState;

/// A FEM body's surface as the FEM side last published it for display: its vertices (body frame)
/// and each vertex's von Mises stress (Pa; a boundary node's: the mean over its tets; an embedded
/// vertex's: its tet's).
struct FemSurfaceFrame {
  std::vector<Vec3> vertices;
  std::vector<float> von_mises_pa;
};
class MeshBvh;

/// The most FEM bodies one world couples.
inline constexpr std::size_t kMaxFemBodies = 4;

/// A contact patch spans at least this many of the surface's mean edge lengths in radius.
inline constexpr double kFemPatchEdges = 1.5;

/// The contact patch radius a FEM body's surface can carry: `configured_m`, raised to
/// kFemPatchEdges times the surface's mean edge length. A smaller patch holds one to three nodes
/// and the force ripples as the tool slides over them (42 % along a 20 mm slide on the bench's
/// 1k-tet block at 6 mm, 12 % at 10 mm, most of it the block's edges).
[[nodiscard]] double fem_patch_radius_m(double configured_m, const TriangleMesh& rest_surface);

/// What one haptic step hands the FEM (haptic path: fixed size, copied).
struct FemLaunch {
  /// The step after which it was taken (WorldState::step_index); 0: none yet.
  std::uint64_t step_index = 0;
  /// FemCoupling::reset() counts up: a launch or update from before a reset is ignored.
  std::uint64_t epoch = 0;
  double time_s = 0.0;
  std::array<Vec3, kMaxTools> p_world{};
  std::array<Vec3, kMaxTools> v_world{};
  std::array<bool, kMaxTools> usable{};
  /// Per (tool t, FEM body b) at [t · kMaxFemBodies + b]: the force on the tool from the body
  /// this step (world frame): what the device rendered, which the tissue takes as its load.
  std::array<Vec3, kMaxTools * kMaxFemBodies> push_world_n{};
  /// Per FEM body: the contact material as the step used it (stiffness clamped to the device).
  std::array<double, kMaxFemBodies> contact_stiffness_n_per_m{};
  std::array<double, kMaxFemBodies> max_force_n{};
};

/// What one FEM update hands the haptic path.
struct FemUpdate {
  std::uint64_t launch_step = 0;  ///< FemLaunch::step_index it answers; 0: none
  std::uint64_t epoch = 0;        ///< the launch's
  std::uint64_t sequence = 0;     ///< updates made so far, this one included
  std::array<LocalContactModel, kMaxTools * kMaxFemBodies> models{};
  /// Per FEM body: its largest node displacement after the update, m, and the FEM step's cost.
  std::array<double, kMaxFemBodies> max_displacement_m{};
  std::array<double, kMaxFemBodies> solve_ms{};
  std::array<int, kMaxFemBodies> cg_iterations{};
};

/// The FEM side's figures, for the run's summary.
struct FemCouplingStats {
  std::uint64_t updates = 0;       ///< FEM updates run
  std::uint64_t adopted = 0;       ///< adopted by the haptic path
  std::uint64_t late_adopted = 0;  ///< adopted after launch + period_steps (real time only)
  std::uint64_t skipped_launches =
      0;                          ///< launches replaced by a newer one before the FEM took them
  std::vector<double> update_ms;  ///< per update, wall-clock ms (all bodies)
};

class FemCoupling {
 public:
  /// Builds a FemBody per FEM body of `model` (fixed nodes resolved: by index, plane, and
  /// attachment to other bodies' segments), the surface mapping (boundary nodes or barycentric
  /// embedding) and the deformed surfaces' BVHs. Throws hapsim::Error naming the body.
  explicit FemCoupling(const WorldModel& model);
  ~FemCoupling();
  FemCoupling(const FemCoupling&) = delete;
  FemCoupling& operator=(const FemCoupling&) = delete;

  [[nodiscard]] std::size_t body_count() const { return bodies_.size(); }
  /// The world body index of FEM body `fem_index`.
  [[nodiscard]] std::size_t world_body(std::size_t fem_index) const;
  /// Steps between launches (and from a launch to its adoption), from the FEM's dt and the
  /// haptic dt: round(dt_fem / dt_haptic), at least 1. Set at the first step.
  [[nodiscard]] std::uint64_t period_steps() const {
    return period_steps_.load(std::memory_order_acquire);
  }

  /// haptic path, before the step's stages: adopts the newest finished update whose adoption
  /// step has come (its models replace the state's FEM contact models).
  void adopt(WorldState& state, double dt_s) noexcept;
  /// haptic path, after the step's stages: every period_steps-th step, publishes a launch.
  void capture(const WorldModel& model, const WorldState& state) noexcept;

  /// FEM side (one thread): runs the newest launch not yet run, if any, and publishes its
  /// update. Returns whether it ran one.
  bool run_pending();

  /// FEM side: a FEM body's deformed surface (the segment's mesh, body frame) and its solver.
  /// Only on the FEM side's thread, or while nothing steps.
  [[nodiscard]] const TriangleMesh& surface(std::size_t fem_index) const;
  [[nodiscard]] const FemBody& body(std::size_t fem_index) const;
  [[nodiscard]] FemBody& body(std::size_t fem_index);
  /// Display thread (one): the newest surface the FEM side published for FEM body `fem_index`
  /// (the segment's vertices, body frame, and their stress) if it changed since the last call,
  /// else null. The FEM
  /// side publishes after every update; the display reads without ever blocking it.
  [[nodiscard]] const FemSurfaceFrame* take_published_surface(std::size_t fem_index);
  /// FEM side: each surface vertex's von Mises stress after the newest update (Pa). Only on the
  /// FEM side's thread, or while nothing steps.
  [[nodiscard]] const std::vector<float>& surface_von_mises_pa(std::size_t fem_index) const;
  /// A FEM body's largest node displacement after the newest update, m (any thread).
  [[nodiscard]] double max_displacement_m(std::size_t fem_index) const {
    return max_displacement_m_.at(fem_index).load(std::memory_order_relaxed);
  }
  /// FEM side: the node weights of a tool's contact patch at the last update (where its load goes
  /// next; empty when the tool is clear of the body). Only while nothing steps.
  [[nodiscard]] const std::vector<FemNodeWeight>& contact_patch(std::size_t fem_index,
                                                                std::size_t tool) const;
  /// Per FEM body: a surface vertex's version counter, bumped by every update (display).
  [[nodiscard]] std::uint64_t surface_version() const {
    return surface_version_.load(std::memory_order_acquire);
  }
  /// FEM side's figures; read while nothing steps.
  [[nodiscard]] const FemCouplingStats& stats() const { return stats_; }
  /// haptic side's figures (read while nothing steps).
  [[nodiscard]] std::uint64_t adopted() const { return adopted_; }
  [[nodiscard]] std::uint64_t late_adopted() const { return late_adopted_; }

  /// Back to rest (nothing steps meanwhile): every body at rest, no launch, no update.
  void reset();

 private:
  struct Body;
  void update_body(std::size_t b, const FemLaunch& launch, FemUpdate& out);

  std::vector<std::unique_ptr<Body>> bodies_;
  /// Per FEM body: its surface's vertices for display, from the FEM side to one display thread.
  std::vector<std::unique_ptr<TripleBuffer<FemSurfaceFrame>>> published_surfaces_;
  std::size_t tool_count_ = 0;
  std::array<double, kMaxTools> tool_radius_m_{};
  double passivity_damping_factor_ = 1.0;  // WorldDescription's: the floor a model asks for
  std::atomic<std::uint64_t> period_steps_{0};
  TripleBuffer<FemLaunch> launches_{FemLaunch{}};
  TripleBuffer<FemUpdate> updates_{FemUpdate{}};
  std::atomic<std::uint64_t> epoch_{1};
  // FEM side.
  std::uint64_t last_run_launch_ = 0;
  std::uint64_t sequence_ = 0;
  FemCouplingStats stats_;
  std::atomic<std::uint64_t> surface_version_{0};
  std::array<std::atomic<double>, kMaxFemBodies> max_displacement_m_{};
  // Haptic side.
  std::uint64_t last_launch_step_ = 0;
  std::uint64_t last_adopted_launch_ = 0;
  std::uint64_t adopted_ = 0;
  std::uint64_t late_adopted_ = 0;
  bool pending_known_ = false;  // the newest update seen by the haptic side is not adopted yet
};

}  // namespace hapsim
