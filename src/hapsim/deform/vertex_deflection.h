// Local vertex deflection (seed 001 §3.1.1, eq. 1): a contact of penetration depth x pushes every
// vertex within d0 of the contact point inward by δ(d) = (x/2)·(cos(π·d/d0) + 1), so δ(0) = x and
// δ(d0) = 0, with d0 = (x + effective contact radius) × the segment's elasticity factor. Released
// vertices recover (reformation) towards their rest positions at a per-segment rate.
//
// Rules chosen here (the paper leaves them open):
//  * Deformation is recomputed from the rest positions every cycle, so it cannot drift.
//  * Several contacts: the deepest deflection per vertex wins (max, not sum) — two fingertips
//    side by side must not push the surface deeper than either fingertip.
//  * A contact deflects only the vertices of its own segment (pressing a muscle does not dent the
//    bone under it); d0 uses that segment's elasticity factor.
//  * Pressing is immediate (the surface follows the probe); releasing follows the recovery law:
//    the gap to the target shrinks as exp(−dt/τ) and by at most v_max·dt per step, and snaps to the
//    target below `rest_tolerance_m`, so it never overshoots and reaches rest in bounded time.
//  * The paper's eq. 1 prints d_p/2 as the amplitude; architecture.md#deformation reads x/2 (δ(0) =
//  x), used here.
//
// Cost (architecture.md#real-time): step() keeps only each vertex's offset along its direction —
// the state eq. 1 and the recovery law need — in the grid's slot order, so a press streams
// through memory. The deformed positions (rest + offset·direction) and normals are display
// data: mesh() writes the positions of the vertices that moved since it was last asked, and
// update_normals() their normals, on whichever call wants them (a viewer, a snapshot, a refit),
// never inside step().
#pragma once

#include "hapsim/core/types.h"
#include "hapsim/deform/point_hash_grid.h"
#include "hapsim/geometry/triangle_mesh.h"

#include <array>
#include <cstddef>
#include <cstdint>
#include <memory>
#include <span>
#include <vector>

namespace hapsim {

/// Per-segment deformation parameters, SI.
struct DeflectionParams {
  /// d0 = (x + r_eff) · elasticity_factor; finite, > 0. Soft tissue large, bone small.
  double elasticity_factor = 1.5;
  /// Reformation time constant τ, seconds; ≥ 0 (0: no exponential lag, only the speed cap).
  double recovery_time_constant_s = 0.1;
  /// Largest reformation speed, m/s; > 0 (infinity: no cap).
  double max_recovery_speed_m_per_s = kInf;
  /// Penetration depths are clamped to this before use, metres; > 0 (infinity: no clamp).
  double max_deflection_m = kInf;
  /// A recovering gap below this snaps to the target, metres; ≥ 0. 10 µm is below anything a
  /// display shows, and ends an exponential recovery ln(100)·τ sooner than 0.1 µm would (on the
  /// VHF knee's wide muscle dents, 31 % fewer vertex updates over the scripted run).
  double rest_tolerance_m = 1e-5;
};

struct VertexDeflectionOptions {
  /// Unit direction in which each vertex moves inward (knee method: towards its group centroid).
  /// Empty → the negated rest vertex normal. Non-zero, finite; normalised on construction.
  std::vector<Vec3> directions;
  /// Segment index of each vertex into `segments`. Empty → every vertex in segment 0.
  std::vector<std::uint32_t> segment_of_vertex;
  /// Parameters per segment. Empty → one segment with default parameters.
  std::vector<DeflectionParams> segments;
  /// Edge of the rest-position hash grid cells, metres. 0 → automatic: twice the mean edge
  /// length, or half a typical contact's d0 when that is larger (a wide dent on a fine mesh
  /// would otherwise look up thousands of small cells).
  double grid_cell_m = 0.0;
  /// Radius of the tools expected to press the surface, metres (≥ 0); only sizes the automatic
  /// grid: a typical contact presses min(max_deflection_m, 10 mm) with this radius.
  double typical_contact_radius_m = 0.005;
};

struct DeflectionContact {
  /// Contact point on the *rest* surface (mesh frame): the probe's projection onto the undeformed
  /// surface, so δ(0) = x brings the surface to the probe tip.
  Vec3 p_mesh = Vec3::Zero();
  /// Penetration depth x, metres (≤ 0: no deflection).
  double penetration_m = 0.0;
  /// Effective radius of the contacting object (fingertip), metres; negative is clamped to 0.
  double contact_radius_m = 0.0;
  /// Segment touched; only its vertices deflect.
  std::uint32_t segment = 0;
};

class VertexDeflection {
 public:
  /// Takes the mesh at rest. Throws hapsim::Error on non-finite vertices, bad parameters, a
  /// zero/non-finite direction, or option arrays whose size does not match the vertex count.
  explicit VertexDeflection(TriangleMesh rest_mesh, VertexDeflectionOptions options = {});

  VertexDeflection(VertexDeflection&&) noexcept = default;
  VertexDeflection& operator=(VertexDeflection&&) noexcept = default;
  VertexDeflection(const VertexDeflection&) = delete;
  VertexDeflection& operator=(const VertexDeflection&) = delete;
  ~VertexDeflection() = default;

  /// One cycle: deflect from `contacts`, let everything else recover for `dt_s` seconds
  /// (non-finite or negative dt counts as 0). Cost O(vertices within d0 + vertices still
  /// recovering); contacts whose reach overlaps are answered in one pass over the grid. Writes
  /// offsets only (deflection_m()); positions wait for mesh(). Invalid contacts are skipped and
  /// counted. haptic path
  void step(std::span<const DeflectionContact> contacts, double dt_s);

  /// Every vertex back to rest at once (reported as moved).
  void reset();

  /// Brings the mesh's positions up to date (as mesh() does), then recomputes the vertex normals
  /// of every vertex whose neighbourhood moved since the last call (angle-weighted, like
  /// TriangleMesh::compute_vertex_normals). Normals are for display only, so step() does not pay
  /// for them: call this at display rate, from the thread that owns the mesh. Allocation-free;
  /// cost O(vertices moved since the last call).
  void update_normals();

  /// Eq. 1: δ(d) = (x/2)·(cos(π·d/d0) + 1) for 0 ≤ d < d0, else 0.
  [[nodiscard]] static double deflection_profile_m(double distance_m, double penetration_m,
                                                   double zero_distance_m);
  /// The same profile from the squared distance, as step() evaluates it (a polynomial in
  /// d²/d0², within 1e-10·x of eq. 1, no sqrt or cos).
  [[nodiscard]] static double deflection_profile_from_squared_m(double distance_sq_m2,
                                                                double penetration_m,
                                                                double zero_distance_m);
  /// The recovery law step() applies to a released vertex's gap to its target over `dt_s`: the
  /// gap shrinks by `decay` = exp(−dt/τ) and by at most v_max·dt, and snaps to 0 below
  /// rest_tolerance_m. haptic path
  [[nodiscard]] static double recover_gap_m(const DeflectionParams& params, double decay,
                                            double gap_m, double dt_s);
  /// d0 = (x + r_eff) · elasticity_factor.
  [[nodiscard]] static double zero_deflection_distance_m(double penetration_m,
                                                         double contact_radius_m,
                                                         double elasticity_factor) {
    return (penetration_m + contact_radius_m) * elasticity_factor;
  }

  /// The deformed mesh. Its vertex positions are written here, lazily: each call first writes
  /// those of the vertices whose offset changed since the last call (O(those vertices),
  /// allocation-free), so what it returns is the surface as of the last step. Vertex normals are
  /// updated by update_normals(). The addresses of the mesh and its arrays never change (safe to
  /// hold in a collision structure, after calling mesh() again before reading the positions).
  /// Only on the thread that steps.
  [[nodiscard]] const TriangleMesh& mesh() const {
    sync_positions();
    return *mesh_;
  }
  /// Vertex v's deformed position: rest + offset·direction, exactly what mesh() writes (the rest
  /// position itself at offset 0). For a caller that wants a few vertices without mesh().
  [[nodiscard]] Vec3 position(std::uint32_t v) const {
    const double offset_m = deflection_m(v);
    return offset_m > 0.0 ? Vec3(rest_[v] + offset_m * direction_[v]) : rest_[v];
  }
  [[nodiscard]] std::span<const Vec3> rest_positions() const { return rest_; }
  [[nodiscard]] std::span<const Vec3> directions() const { return direction_; }
  /// Current inward displacement of vertex v along its direction, metres (≥ 0).
  [[nodiscard]] double deflection_m(std::uint32_t v) const {
    return slots_[slot_of_vertex_[v]].offset_m;
  }
  /// Vertices whose offset (so position) changed in the last step()/reset(), each once.
  [[nodiscard]] std::span<const std::uint32_t> moved_vertices() const { return moved_vertices_; }
  /// Triangles with a moved corner in the last step()/reset(), each once (refit these).
  /// Gathered on the first call after a step, so a step that nobody refits does not pay for it.
  [[nodiscard]] std::span<const std::uint32_t> moved_triangles() const;
  /// Largest current deflection after the last step, metres.
  [[nodiscard]] double max_deflection_m() const { return max_deflection_m_; }
  /// Vertices currently away from rest.
  [[nodiscard]] std::size_t deformed_vertex_count() const { return active_.size(); }
  [[nodiscard]] std::size_t rejected_contacts() const { return rejected_; }
  [[nodiscard]] const PointHashGrid& grid() const { return *grid_; }
  [[nodiscard]] std::size_t segment_count() const { return segments_.size(); }

 private:
  /// Per vertex, in the grid's slot order (PointHashGrid::slot_x/y/z), what step() reads and
  /// writes: one cache line holds it for 2-3 vertices that lie side by side.
  struct Slot {
    double offset_m = 0.0;  ///< inward displacement now (≥ 0); > 0 exactly while in active_
    double target_m = 0.0;  ///< this step's target, valid when stamp == stamp_
    std::uint32_t stamp = 0;
    /// == display_epoch_: already listed in stale_ (its position is not yet in the mesh).
    /// Display bookkeeping: the lazy (const) calls may reset it.
    mutable std::uint32_t stale_epoch = 0;
  };
  /// A valid contact ready for the grid pass (eq. 1's x and d0, the query box).
  struct PreparedContact {
    Vec3 p_mesh = Vec3::Zero();
    Vec3 lo = Vec3::Zero();
    Vec3 hi = Vec3::Zero();
    double x_m = 0.0;
    double r2_m2 = 0.0;  ///< d0²
    double inv_d0_sq = 0.0;
    double cells = 0.0;  ///< grid cells its box spans
    std::uint32_t segment = 0;
    std::uint32_t group = 0;
  };
  static constexpr std::size_t kBatch = 16;

  void set_offset(std::uint32_t slot, double offset_m);
  void next_stamp();
  void next_moved_stamp();
  void press(std::span<const DeflectionContact> contacts, double dt_s);
  void press_group(const PreparedContact* first, std::size_t count, const Vec3& lo, const Vec3& hi,
                   bool settle_now, double dt_s);
  void settle(std::uint32_t slot, double dt_s);
  void sync_positions() const;
  [[nodiscard]] bool same_contacts_as_last(std::span<const DeflectionContact> contacts) const;
  [[nodiscard]] double recovered_gap_m(std::uint32_t segment, double gap_m, double dt_s) const;

  std::unique_ptr<TriangleMesh> mesh_;
  std::vector<Vec3> rest_;
  std::vector<Vec3> direction_;
  std::vector<std::uint32_t> segment_of_vertex_;
  std::vector<DeflectionParams> segments_;
  std::unique_ptr<PointHashGrid> grid_;
  /// Vertex → incident triangles (CSR), for local refit lists and normals.
  std::vector<std::uint32_t> vertex_tri_start_;
  std::vector<std::uint32_t> vertex_tris_;

  /// The haptic state, slot order, and the two permutations.
  std::vector<Slot> slots_;
  std::vector<std::uint32_t> vertex_of_slot_;
  std::vector<std::uint32_t> slot_of_vertex_;
  /// Segment of each slot (only read when there is more than one segment).
  std::vector<std::uint32_t> segment_of_slot_;
  /// Marks targets "seen in this cycle", so nothing is cleared per cycle.
  std::uint32_t stamp_ = 0;
  /// Generation of moved_vertices_/moved_triangles_ (advances every step, also when held).
  std::uint32_t moved_stamp_ = 0;
  /// Last step's contacts when every touched vertex reached its target (a held press repeats
  /// them); at most kMaxHeldContacts, reserved once.
  static constexpr std::size_t kMaxHeldContacts = 64;
  std::vector<DeflectionContact> last_contacts_;
  bool held_ = false;
  /// Slots away from rest (recovering or held), pre-sized to the vertex count.
  std::vector<std::uint32_t> active_;
  /// Slots within reach of this step's contacts.
  std::vector<std::uint32_t> touched_;
  std::vector<std::uint32_t> moved_vertices_;
  /// Scratch of step(): a batch of valid contacts, and the groups that share a grid pass (box
  /// and the cells it spans).
  std::vector<PreparedContact> prepared_;
  std::array<Box3, kBatch> group_box_;
  std::array<double, kBatch> group_cells_{};
  /// Scratch of press_group(): per slot of a cell, the deepest δ so far (< 0: not reached).
  std::vector<double> deepest_scratch_;
  /// This step's touched vertices all reached their targets (a held press can skip the next).
  bool settled_ = true;
  // Filled lazily by moved_triangles() (a cache of the last step's moved vertices).
  mutable std::vector<std::uint32_t> moved_triangles_;
  mutable std::vector<std::uint32_t> triangle_stamp_lazy_;
  mutable bool moved_triangles_ready_ = true;
  /// Display bookkeeping: slots whose offset changed since the positions were last written
  /// (listed by step(), each once per display epoch; written out by mesh()); then the vertices
  /// written since the last update_normals(), whose one-ring's normals are stale.
  mutable std::vector<std::uint32_t> stale_;
  mutable std::uint32_t display_epoch_ = 1;
  mutable std::vector<std::uint32_t> moved_since_normals_;
  mutable std::vector<std::uint8_t> moved_since_normals_flag_;
  /// Scratch of update_normals(): vertices whose normal is recomputed, each once.
  std::vector<std::uint32_t> normals_pending_;
  std::vector<std::uint8_t> normal_pending_flag_;
  /// Per segment, exp(−dt/τ) for this step's dt: one exp per segment instead of per vertex.
  std::vector<double> decay_per_segment_;
  double max_deflection_m_ = 0.0;
  std::size_t rejected_ = 0;
};

}  // namespace hapsim
