// A tetrahedral mesh (linear tetrahedra): the volume a FEM body is made of (SPEC §12,
// architecture.md#deformation). Plain data like TriangleMesh; its invariants are checked by
// validate_tet_mesh(), and every function here accepts any input (NaN, out-of-range indices) and
// reports instead of crashing.
#pragma once

#include "hapsim/core/types.h"
#include "hapsim/geometry/triangle_mesh.h"

#include <array>
#include <cstddef>
#include <cstdint>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

namespace hapsim {

/// Node indices of one tetrahedron, positively oriented: (p1−p0)·((p2−p0)×(p3−p0)) > 0.
using TetIndices = std::array<std::uint32_t, 4>;

struct TetMesh {
  /// Node positions in the mesh's own frame, metres.
  std::vector<Vec3> nodes;
  std::vector<TetIndices> tets;
  /// Per tetrahedron, its region (a Gmsh physical group, a TetGen region attribute, a VTK cell
  /// data array): what a material is assigned to. Empty means every tet is region 0.
  std::vector<std::int32_t> regions;

  [[nodiscard]] std::size_t node_count() const { return nodes.size(); }
  [[nodiscard]] std::size_t tet_count() const { return tets.size(); }
  [[nodiscard]] std::int32_t region(std::size_t tet) const {
    return regions.empty() ? 0 : regions[tet];
  }
  /// Signed volume of tet `t` (positive when positively oriented), m³.
  [[nodiscard]] double signed_volume(std::size_t t) const;
  [[nodiscard]] double volume() const;
  [[nodiscard]] Box3 bounds() const;
  /// Uniform scale (a file in millimetres: 1e-3).
  void scale(double factor);
  void transform(const Iso3& X_new_old);
};

/// The mesh's boundary: every triangle face that belongs to exactly one tet, wound outward (CCW
/// seen from outside), as a surface over the boundary nodes only. `node_of_vertex[v]` is the tet
/// node of surface vertex v.
/// `tet_of_triangle[t]` is the tet whose face surface triangle t is (added for the embedding and
/// for contact: a load on a boundary triangle goes to that tet's nodes).
struct TetBoundary {
  TriangleMesh surface;
  std::vector<std::uint32_t> node_of_vertex;
  std::vector<std::uint32_t> tet_of_triangle;
};
[[nodiscard]] TetBoundary tet_boundary(const TetMesh& mesh);

/// Shape quality (tets with a non-finite or out-of-range node are skipped and counted apart).
struct TetMeshQuality {
  std::size_t tets = 0;
  std::size_t nodes = 0;
  /// Smallest and largest dihedral angle over all tets, degrees (70.53° for a regular tet).
  double min_dihedral_deg = 0.0;
  double max_dihedral_deg = 0.0;
  /// Largest aspect ratio: longest edge / (2·√6 · inradius), 1 for a regular tet.
  double max_aspect_ratio = 0.0;
  double min_volume_m3 = 0.0;
  double total_volume_m3 = 0.0;
  std::size_t inverted = 0;  ///< signed volume < 0 (and not degenerate)
  /// |volume| ≤ 1e-12 · bounds diagonal³ (flat or repeated node). Degenerate tets count in the
  /// volumes but not in the dihedral angles or aspect ratio (they have none worth the name).
  std::size_t degenerate = 0;
  std::size_t components = 0;  ///< connected pieces (tets sharing a node are connected)
  std::size_t unused_nodes = 0;
  /// Tets left out of every measure above: a node index out of range, or a non-finite node.
  std::size_t out_of_range = 0;
  std::size_t non_finite = 0;
};
[[nodiscard]] TetMeshQuality tet_mesh_quality(const TetMesh& mesh);

/// Throws hapsim::Error("SOURCE", "element N: ...") for the first unusable element: a node index
/// out of range, a non-finite node it uses, an inverted or degenerate tet; then for tets that
/// overlap through a face (a duplicated element, two tets on the same side of a face, a face
/// shared by three); and ("SOURCE", "...")
/// for an empty mesh, more than one connected piece (`allow_disconnected` false) or a region list
/// whose length differs from the tets'. `source` names the file (or the scene's JSON pointer).
/// Element numbers are 0-based indices into `tets`, as the message says.
void validate_tet_mesh(const TetMesh& mesh, std::string_view source,
                       bool allow_disconnected = false);

/// What validate_tet_mesh() would throw, without throwing: `message` is its text without the
/// source, `element` the offending element when there is one (so a reader can add the file's
/// line to it). Empty when the mesh is valid.
struct TetMeshProblem {
  std::string message;
  std::optional<std::size_t> element;
};
[[nodiscard]] std::optional<TetMeshProblem> find_tet_mesh_problem(const TetMesh& mesh,
                                                                  bool allow_disconnected = false);

/// A box [0, size] (mesh frame), `cells` cubes along each axis, each cut into 6 tetrahedra
/// sharing the cube's main diagonal (conforming between neighbours): 6·nx·ny·nz tets.
[[nodiscard]] TetMesh make_tet_block(const Vec3& size_m, const std::array<int, 3>& cells);

/// A ball of radius `radius_m` centred at the origin, about `target_tets` tetrahedra (between
/// about 0.6 and 1 times the target, at least 48): the cubes of a block mesh of the bounding cube
/// that lie wholly inside are kept and their boundary nodes projected onto the sphere
/// (conforming, positively oriented, no tet squashed below a fifth of its volume, a closed
/// manifold boundary). Slivers the projection flattens are dropped; where that is not possible a
/// node stays between the staircase and the sphere, which happens on coarse balls (below ~5000
/// tets) only: from 5000 tets every boundary node is on the sphere.
[[nodiscard]] TetMesh make_tet_ball(double radius_m, std::size_t target_tets);

}  // namespace hapsim
