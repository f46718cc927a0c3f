// The read-only half of a world (MuJoCo's mjModel): everything built once from a WorldDescription
// — per segment its rest-shape proximity query, frame and material; the tools; the hand model when
// a glove drives the tools — and never changed by a step. The per-step half is WorldState
// (world_state.h); step() (world_step.h) reads this and writes that.
#pragma once

#include "hapsim/collision/proximity_query.h"
#include "hapsim/core/types.h"
#include "hapsim/world/indices.h"
#include "hapsim/world/world_description.h"

#include <cstddef>
#include <memory>
#include <optional>
#include <span>
#include <string>
#include <vector>

namespace hapsim {

struct WorldOptions {
  /// Stiffness of every material is clamped to this (the device's rated maximum keeps the
  /// rendering stable on it); infinity: no clamp.
  double max_stiffness_n_per_m = kInf;
  /// God-object parameters (the radius comes from each tool).
  double proxy_max_substep_m = 2.5e-4;
  int proxy_max_iterations = 16;
};

class SphereTree;

/// One body as a step sees it: where its segments are in the flat list and, for a dynamic body,
/// its mass properties.
struct BodyModel {
  BodyKind kind = BodyKind::kStatic;
  FlatSegment first_segment{0};  ///< its segment 0's flat index
  std::size_t segment_count = 0;
  bool sheet = false;  ///< a Gaussian sheet (one segment)
  /// A sheet: how deep its elastic field sinks under a 1 N push, metres (its profile at d = 0).
  double sheet_compliance_m_per_n = 0.0;
  /// A sheet: per dynamic segment (model.dynamic_segments() order), how many of that segment's
  /// contact springs press the sheet at once, weighted by how far the sheet's dent under one
  /// reaches the others (1 for a ball; a cube's flat face: its four corners, less their spread).
  std::vector<double> sheet_press_springs;
  // Dynamic bodies only.
  /// Its index in WorldModel::dynamic_bodies(); −1 for a body that does not move by itself.
  std::int32_t dynamic_index = -1;
  double mass_kg = 0.0;
  Vec3 com_body = Vec3::Zero();
  Mat3 inertia_body_kg_m2 = Mat3::Identity();
  Mat3 inverse_inertia_body = Mat3::Identity();
  /// A dynamic body of one exactly spherical segment meets other bodies through its centre and
  /// radius (exact); otherwise through its meshes' vertices (stage_body_contacts.cpp).
  std::optional<ExactSphere> sphere;
};

/// One segment of one body, flattened over all bodies (flat index = the body's first segment +
/// the segment's index in its body).
struct SegmentModel {
  std::size_t body = 0;
  LocalSegment index_in_body{0};
  const SegmentDescription* description = nullptr;
  std::uint32_t material = 0;
  ContactResponse response = ContactResponse::kProxy;
  bool deformable = false;
  bool sheet = false;  ///< a Gaussian sheet: contact with its live field (WorldState), not rest
  /// A FEM body's surface: touched only through its local contact models (stage_fem_contacts),
  /// never through its rest query or the god-object.
  bool fem = false;
  bool dynamic = false;
  /// The body's pose at the start (a dynamic body's current pose is in WorldState::bodies).
  Iso3 X_world_body = Iso3::Identity();
  Iso3 X_body_world = Iso3::Identity();
  /// Where the surface can be, body frame (a sheet's bounds include how deep it can sink).
  Box3 rest_bounds_body;
  /// The rest surface's query in the body frame (the body's contact method): what a step uses.
  std::unique_ptr<ProximityQuery> rest_query;
  /// Sphere tree of the rest surface for body-against-body contact (paper 000 §3.1: both bodies'
  /// trees descended where parent spheres overlap, then refined exactly); built when the world
  /// has dynamic bodies (a kinematic body's always: a controller checks where it enters others),
  /// and not for sheets (their field answers directly). A CSG solid's
  /// or exact sphere's tree is over its polygonised mesh: it finds candidate vertices, the exact
  /// solid refines.
  std::unique_ptr<SphereTree> body_tree;
};

/// A press on a sheet that would not settle: which sheet (body index), who presses (a body's
/// index, −1 for the tools) and the two stiffnesses.
struct SheetPress {
  std::size_t sheet_body = 0;
  std::ptrdiff_t presser = -1;
  double stiffness_n_per_m = 0.0;
  double sheet_stiffness_n_per_m = 0.0;
};

class WorldModel {
 public:
  /// Builds every query structure. Throws hapsim::Error naming the body, segment or tool on an
  /// unusable description (empty mesh, bad material index, too many proxy segments, bad tool).
  WorldModel(WorldDescription description, WorldOptions options);
  ~WorldModel();
  WorldModel(const WorldModel&) = delete;
  WorldModel& operator=(const WorldModel&) = delete;

  [[nodiscard]] const WorldDescription& description() const { return description_; }
  [[nodiscard]] const WorldOptions& options() const { return options_; }
  /// The hand the glove drives, or null when the tools sit at device offsets.
  [[nodiscard]] const HandModel* hand() const { return hand_.get(); }
  [[nodiscard]] const std::vector<SegmentModel>& segments() const { return segments_; }
  [[nodiscard]] const std::vector<BodyModel>& bodies() const { return bodies_; }
  /// Indices of the dynamic bodies, in body order.
  [[nodiscard]] const std::vector<std::size_t>& dynamic_bodies() const { return dynamic_bodies_; }
  /// Flat indices of the dynamic bodies' segments, in flat order.
  [[nodiscard]] const std::vector<std::size_t>& dynamic_segments() const {
    return dynamic_segments_;
  }
  /// Indices of the FEM bodies (BodyDeformation::kFem), in body order: FEM body b is
  /// fem_bodies()[b] (world/fem_coupling.h).
  [[nodiscard]] const std::vector<std::size_t>& fem_bodies() const { return fem_bodies_; }
  /// Whether some dynamic body is not an exact sphere (it meets others through its vertices).
  [[nodiscard]] bool has_dynamic_meshes() const { return has_dynamic_meshes_; }
  /// The flat index of `body`'s segment `segment` (body-local): its first segment + segment.
  [[nodiscard]] FlatSegment flat_segment(BodyIndex body, LocalSegment segment) const {
    return FlatSegment{body_first_segment_.at(body.index()).value + segment.index()};
  }
  [[nodiscard]] std::size_t tool_count() const { return description_.tools.size(); }
  [[nodiscard]] std::size_t proxy_segment_count() const { return proxy_segments_; }
  [[nodiscard]] std::size_t penalty_segment_count() const { return penalty_segments_; }
  [[nodiscard]] double max_tool_radius_m() const { return max_tool_radius_m_; }
  /// Whether every press on a sheet settles with these contact materials (indexed like the
  /// description's): each spring that presses a sheet — a tool's (clamped to the device's
  /// rating), a dynamic body's (both materials in series) — is softer than the sheet gives way
  /// under it. Otherwise false, with the first that does not in `unsettled`. The model checks
  /// its own materials at build; a live edit is checked before it is taken. haptic path
  [[nodiscard]] bool sheet_presses_settle(std::span<const ContactMaterial> materials,
                                          SheetPress* unsettled = nullptr) const noexcept;
  /// What the model decided that the description did not say, one sentence each, to be said
  /// once where a user reads it: a knee-method body's proxy segments answering exactly, a
  /// segment the knee method answers far off the exact surface (world/knee_method_query.h).
  [[nodiscard]] const std::vector<std::string>& notes() const { return notes_; }
  /// Bytes of all rest-shape query structures (meshes excluded).
  [[nodiscard]] std::size_t query_memory_bytes() const;
  [[nodiscard]] double build_ms() const { return build_ms_; }

 private:
  void check_sheet_contacts() const;

  WorldDescription description_;
  std::vector<std::string> notes_;
  WorldOptions options_;
  std::unique_ptr<HandModel> hand_;
  std::vector<SegmentModel> segments_;
  std::vector<BodyModel> bodies_;
  std::vector<std::size_t> dynamic_bodies_;
  std::vector<std::size_t> dynamic_segments_;
  std::vector<std::size_t> fem_bodies_;
  bool has_dynamic_meshes_ = false;
  std::vector<FlatSegment> body_first_segment_;
  std::size_t proxy_segments_ = 0;
  std::size_t penalty_segments_ = 0;
  double max_tool_radius_m_ = 0.0;
  double build_ms_ = 0.0;
};

}  // namespace hapsim
