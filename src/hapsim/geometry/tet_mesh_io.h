// Reading tetrahedral meshes written by external meshers (run as programs, never linked: Gmsh,
// TetGen, Netgen, or anything that writes VTK): Gmsh MSH 4.1 ASCII, TetGen .node/.ele, and legacy
// VTK ASCII unstructured grids. Each reader is bounded (core/text_file.h), never crashes or hangs
// on a hostile file, and throws hapsim::Error naming the file and the line (or element) on
// anything it cannot use. Linear tetrahedra only: other elements of a volume are refused by name,
// surface and line elements in a Gmsh file are skipped (a mesher writes them beside the volume).
// The result is validated (validate_tet_mesh) before it is returned, and tets are re-oriented
// positively when a file lists them the other way round consistently (TetGen's and Gmsh's
// conventions differ); a file with both orientations is refused at its first inverted element.
// An element's message names the file's line and the element's 0-based index among the tets
// ("m.msh:57: element 17: inverted (signed volume -1.2e-09 file units^3)"). Coordinates are in
// the file's units (TetMesh::scale converts), and so are the volumes in messages.
#pragma once

#include "hapsim/geometry/tet_mesh.h"

#include <filesystem>
#include <string_view>

namespace hapsim {

/// Gmsh MSH 4.1 ASCII ($MeshFormat 4.1 0 8; $Entities for physical tags; $Nodes; $Elements:
/// type 4 = 4-node tetrahedron). A tet's region is its volume entity's first physical tag, else the
/// entity tag.
[[nodiscard]] TetMesh read_gmsh_msh4(const std::filesystem::path& path);
[[nodiscard]] TetMesh parse_gmsh_msh4(std::string_view text, std::string_view source);

/// TetGen: `PATH.node` and `PATH.ele` (either may be given; the other is found beside it). Node
/// numbering from 0 or 1 as the file says; the .ele's region attribute, when present, is the
/// region. `source` for parse_tetgen is PATH without the extension: messages name
/// "SOURCE.node:LINE" or "SOURCE.ele:LINE". '#' starts a comment, as in TetGen.
[[nodiscard]] TetMesh read_tetgen(const std::filesystem::path& node_or_ele_path);
[[nodiscard]] TetMesh parse_tetgen(std::string_view node_text, std::string_view ele_text,
                                   std::string_view source);

/// Writes `mesh` as TetGen's `PATH.node` and `PATH.ele` (PATH without the extension): nodes
/// numbered from 0, coordinates with 17 significant digits (read back bit for bit), the region as
/// the .ele's one attribute, tets as stored. The same mesh gives the same bytes. Throws
/// hapsim::Error naming the file when it cannot be written (a full disk included).
void write_tetgen(const TetMesh& mesh, const std::filesystem::path& path_without_extension);

/// Legacy VTK ASCII, DATASET UNSTRUCTURED_GRID (POINTS, CELLS, CELL_TYPES: 10 = tetra; an
/// integer CELL_DATA scalar named region, gmsh:physical or CellEntityIds, when present, is the
/// region). CELLS in the 5.1 layout (OFFSETS, CONNECTIVITY: meshio's default) are read too, and
/// a CELL_DATA FIELD array by those names counts like a SCALARS one. Vertex, line and surface
/// cells are skipped, as in a Gmsh file.
[[nodiscard]] TetMesh read_vtk_unstructured(const std::filesystem::path& path);
[[nodiscard]] TetMesh parse_vtk_unstructured(std::string_view text, std::string_view source);

/// By extension: .msh, .node/.ele, .vtk. Throws naming the file for anything else.
[[nodiscard]] TetMesh read_tet_mesh(const std::filesystem::path& path);

/// Whether `path` names a tet mesh file by its extension (.msh, .node, .ele, .vtk).
[[nodiscard]] bool is_tet_mesh_path(const std::filesystem::path& path);

}  // namespace hapsim
