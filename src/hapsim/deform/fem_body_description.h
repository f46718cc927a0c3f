// What a FEM body is made of, as plain data (a scene's "deformation": "fem" body, or code): the
// tetrahedral volume, a material per region, how it is held (fixed nodes), its solver settings
// and the surface that is touched and drawn. The world (world/fem_coupling.h) builds a FemBody
// (fem_body.h) from it and couples it to the haptic cycle (architecture.md#deformation).
#pragma once

#include "hapsim/deform/fem_body.h"
#include "hapsim/geometry/tet_mesh.h"

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

namespace hapsim {

/// Nodes held by another body's segment (a tissue attached to a bone, a block on a table): every
/// node whose rest position is inside that segment or within `within_m` of its surface is fixed.
struct FemAttachment {
  std::string body;
  /// Empty: every segment of the body.
  std::string segment;
  double within_m = 1e-3;
  /// Where it was given ("scene.json:/bodies/1/fem/fixed/attached_to/0"), for errors.
  std::string where;
};

struct FemBodyDescription {
  /// The volume, in the body frame (metres).
  TetMesh tets;
  std::vector<FemRegionMaterial> materials;
  FemOptions options;
  /// Fixed nodes by index, by a plane (nodes with z ≤ this in the body frame) and by attachment;
  /// a node may be named by several. A FEM body needs at least one.
  std::vector<std::uint32_t> fixed_nodes;
  std::optional<double> fixed_below_z_m;
  std::vector<FemAttachment> attached_to;
  /// The segment's mesh is the surface touched and drawn: the tets' boundary (false), or a finer
  /// triangle mesh embedded in the tets by barycentric coordinates (true).
  bool embedded_surface = false;
  /// Around a tool's contact point, the surface nodes within this radius share its load (the
  /// tool's own radius when larger): a point load on one node is mesh-dependent (singular in the
  /// continuum), a patch the size of the fingertip is not.
  double contact_patch_radius_m = 0.004;
  /// A tool farther than this from the surface gets no contact model (free space).
  double contact_margin_m = 0.01;
  /// Where it came from ("scene.json:/bodies/1", "block.msh"), for errors.
  std::string source;
};

}  // namespace hapsim
