// Mesh validation and repair: what is wrong with a triangle mesh (counts per defect), what a
// loader does about each defect (ignore, warn, repair, refuse), and the repairs themselves.
// Every function here accepts any input — NaN coordinates, out-of-range indices, garbage — and
// reports instead of crashing; nothing here asserts on mesh content.
#pragma once

#include "hapsim/geometry/triangle_mesh.h"

#include <array>
#include <cstddef>
#include <string>
#include <string_view>
#include <vector>

namespace hapsim {

/// The defects validate_mesh() counts, each with its own policy entry.
enum class MeshDefect {
  kNonFiniteVertex,          ///< a vertex coordinate is NaN or ±inf
  kOutOfRangeIndex,          ///< a triangle names a vertex that does not exist
  kDegenerateTriangle,       ///< repeated vertex index or (near-)zero area
  kDuplicateTriangle,        ///< same three vertices as an earlier triangle (any order)
  kOpenEdge,                 ///< edge used by one triangle only (a hole / boundary)
  kNonManifoldEdge,          ///< edge used by more than two triangles
  kInconsistentOrientation,  ///< two triangles traverse their shared edge in the same direction
  kInvertedComponent,        ///< closed component with negative volume ("inside out")
  kUnusedVertex,             ///< vertex no triangle uses
};
inline constexpr std::size_t kMeshDefectCount = 9;

/// Short stable name, e.g. "open_edges" (used in JSON and messages).
std::string_view to_string(MeshDefect defect);

/// What a loader does when a defect is present.
enum class DefectAction {
  kIgnore,  ///< accept silently
  kWarn,    ///< accept, log a warning and note it in the report
  kRepair,  ///< repair if a repair exists (see repair_mesh), with a warning; else as kWarn
  kRefuse,  ///< throw hapsim::Error naming the file
};
std::string_view to_string(DefectAction action);

/// Per-defect actions. Defaults: unusable geometry (non-finite, out-of-range) is refused;
/// removable defects (degenerate, duplicate, unused) are dropped; inside-out closed components
/// are flipped; topology defects that have no safe automatic fix (open, non-manifold) and
/// inconsistent orientation are accepted with a warning (contact on such a mesh still works
/// per triangle, but inside/outside answers may be wrong).
struct ValidationPolicy {
  std::array<DefectAction, kMeshDefectCount> actions{
      DefectAction::kRefuse,  // non-finite vertex
      DefectAction::kRefuse,  // out-of-range index
      DefectAction::kRepair,  // degenerate triangle
      DefectAction::kRepair,  // duplicate triangle
      DefectAction::kWarn,    // open edge
      DefectAction::kWarn,    // non-manifold edge
      DefectAction::kWarn,    // inconsistent orientation
      DefectAction::kRepair,  // inverted component
      DefectAction::kRepair,  // unused vertex
  };

  [[nodiscard]] DefectAction& operator[](MeshDefect d) {
    return actions[static_cast<std::size_t>(d)];
  }
  [[nodiscard]] DefectAction operator[](MeshDefect d) const {
    return actions[static_cast<std::size_t>(d)];
  }
  /// Refuse every defect except unused vertices (dropped): for inputs that must be watertight.
  static ValidationPolicy strict();
  /// Repair what can be repaired, warn about the rest, refuse only unusable geometry.
  static ValidationPolicy repair_all();
  /// Accept anything, only warn (for inspecting broken files).
  static ValidationPolicy warn_only();
};

/// Two faces sharing an edge are folded when their normals are more than this apart (an interior
/// angle under 37 degrees: sharper than any ridge of the anatomy, far sharper than a box's 90).
inline constexpr double kFoldAngleDeg = 143.0;

/// Whether two faces' unit normals meet at a fold (see MeshReport::folded_edges).
[[nodiscard]] bool is_fold(const Vec3& unit_normal_a, const Vec3& unit_normal_b);

struct MeshValidationOptions {
  /// A triangle is degenerate when twice its area is at most this fraction of the squared
  /// bounding-box diagonal (scale-free, so millimetre and metre files behave alike).
  double degenerate_area_rel = 1e-12;
};

/// What validate_mesh() found. Counts refer to the mesh as given.
struct MeshReport {
  std::size_t vertex_count = 0;
  std::size_t triangle_count = 0;
  /// Distinct undirected edges. Edge, Euler and closedness facts use the in-range triangles
  /// that are neither degenerate nor duplicates (each defect is reported once, under its name).
  std::size_t edge_count = 0;

  std::size_t non_finite_vertices = 0;
  std::size_t out_of_range_triangles = 0;  ///< triangles with at least one bad index
  std::size_t degenerate_triangles = 0;    ///< repeated index or near-zero area
  std::size_t duplicate_triangles = 0;     ///< later copies of an earlier triangle
  std::size_t open_edges = 0;              ///< edges with one triangle
  std::size_t non_manifold_edges = 0;      ///< edges with more than two triangles
  std::size_t inconsistent_edges = 0;      ///< two-triangle edges traversed the same way twice
  std::size_t inverted_components = 0;     ///< closed, consistent, negative volume, not a cavity
  std::size_t unused_vertices = 0;
  std::size_t components = 0;  ///< connected via shared vertices
  /// Manifold edges whose two faces turn back on each other (normals more than kFoldAngleDeg
  /// apart: a fin a simplification or a marching-cubes corner left). Not a defect of the
  /// topology, but inside/outside from the closest point's pseudo-normal is unreliable beside
  /// them, and such fins usually cross a neighbouring face.
  std::size_t folded_edges = 0;

  /// Watertight: triangles present, no open, non-manifold or inconsistent edge, no bad index.
  bool closed = false;
  /// V − E + F over used vertices (2 per closed genus-0 component).
  long long euler_characteristic = 0;
  /// Divergence-theorem volume (m³ for a mesh in metres); meaningful only when closed.
  double signed_volume = 0.0;
  double surface_area = 0.0;
  /// Bounds of the finite vertices (empty if none).
  Box3 bounds;

  /// What a loader did about the defects (warnings, repairs), in order. validate_mesh() leaves
  /// it empty.
  std::vector<std::string> notes;

  /// Count for one defect kind.
  [[nodiscard]] std::size_t count(MeshDefect defect) const;
  /// True if any defect count is non-zero.
  [[nodiscard]] bool has_defects() const;
  /// One line per fact, e.g. "18918 triangles, 9461 vertices, closed, 1 component; no defects".
  [[nodiscard]] std::string summary() const;
  /// The report as a JSON object (counts by to_string(MeshDefect) name, closed, volume, …).
  [[nodiscard]] std::string to_json(int indent = -1) const;
};

/// Counts every defect of `mesh`. Never throws on mesh content; O(T log T).
[[nodiscard]] MeshReport validate_mesh(const TriangleMesh& mesh,
                                       const MeshValidationOptions& options = {});

/// What repair_mesh() changed.
struct MeshRepairStats {
  std::size_t dropped_non_finite = 0;  ///< triangles touching a non-finite vertex
  std::size_t dropped_out_of_range = 0;
  std::size_t dropped_degenerate = 0;
  std::size_t dropped_duplicate = 0;
  std::size_t reoriented_triangles = 0;  ///< flipped to agree with their neighbours
  std::size_t flipped_components = 0;    ///< inside-out components turned outward
  std::size_t removed_vertices = 0;      ///< unused (and non-finite) vertices removed

  [[nodiscard]] bool any() const;
  /// E.g. "dropped 3 degenerate triangles; flipped 1 inside-out component".
  [[nodiscard]] std::string summary() const;
};

/// Applies the repair for every defect whose action is kRepair (only those), in a safe order:
/// drop bad triangles → orient consistently → flip inside-out components → remove unused
/// vertices. Vertex normals are recomputed if anything changed and the mesh had normals.
MeshRepairStats repair_mesh(TriangleMesh& mesh, const ValidationPolicy& policy,
                            const MeshValidationOptions& options = {});

/// Reverses the winding of every triangle (and negates vertex normals).
void flip_orientation(TriangleMesh& mesh);

}  // namespace hapsim
