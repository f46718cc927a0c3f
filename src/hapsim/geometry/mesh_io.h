// Loading and saving triangle meshes through Assimp (OBJ, STL ASCII/binary, PLY, glTF/GLB, and
// whatever else Assimp reads), with a unit scale, vertex welding and validation on load.
// Assimp stays out of this header: it is a private dependency of the headless library.
#pragma once

#include "hapsim/geometry/mesh_validation.h"
#include "hapsim/geometry/triangle_mesh.h"
#include "hapsim/geometry/vertex_welding.h"

#include <cstddef>
#include <filesystem>
#include <optional>
#include <string_view>

namespace hapsim {

struct MeshLoadOptions {
  /// Metres per file unit: 1e-3 for a file in millimetres (the knee), 1 for metres (the robot).
  double scale = 1.0;
  /// Merge vertices by position so STL triangle soup (and OBJ/glTF seams) become one connected
  /// surface. Off keeps the file's own indexing (only fully identical vertices are shared).
  bool weld = true;
  /// Vertices closer than this (after scaling, metres) are merged; 0 merges exact duplicates.
  double weld_tolerance_m = 0.0;
  /// Alternatively, a tolerance relative to the bounding-box diagonal (the larger one wins).
  double weld_tolerance_rel = 0.0;
  /// What to do about each defect validation finds.
  ValidationPolicy policy;
  MeshValidationOptions validation;
  /// Compute angle-weighted vertex normals (from the welded geometry, not the file's normals).
  bool compute_normals = true;
};

/// Loads every triangle of every mesh in `path`, node transforms applied, merged into one mesh,
/// scaled by `options.scale`, welded, validated and repaired per `options.policy`.
/// Points and lines in the file are skipped (counted in the report notes).
/// Throws hapsim::Error{path, message} when the file is missing or unreadable, the format is
/// unknown or the content corrupt, it holds no triangles, or a defect the policy refuses is
/// found. `report`, if given, receives what validation found in the file as read (before
/// repairs) and notes on every warning and repair.
[[nodiscard]] TriangleMesh load_mesh(const std::filesystem::path& path,
                                     const MeshLoadOptions& options = {},
                                     MeshReport* report = nullptr);

/// load_mesh after the importer: `mesh` as the file gave it (unscaled; indices, coordinates and
/// defects as read: out-of-range, NaN and all) and the point/line primitives skipped, scaled,
/// welded, validated and repaired per `options`; errors name `path`. Its own function so the
/// fuzz target mesh_soup (docs/fuzzing.md) reaches our half of a load in process, where the
/// importer's half needs a child process per file.
[[nodiscard]] TriangleMesh finish_imported_mesh(TriangleMesh mesh, std::size_t skipped_primitives,
                                                const std::filesystem::path& path,
                                                const MeshLoadOptions& options,
                                                MeshReport* report = nullptr);

struct MeshSaveOptions {
  /// File units per metre on writing, e.g. 1e3 to write millimetres.
  double scale = 1.0;
  /// Binary STL / PLY (smaller, exact floats); ASCII if false. OBJ is always text.
  bool binary = true;
};

/// Writes `mesh` by extension: .obj, .stl, .ply, .gltf, .glb. Throws hapsim::Error{path, …} on
/// an unknown extension, an empty or invalid mesh (bad indices), or a write failure.
void save_mesh(const std::filesystem::path& path, const TriangleMesh& mesh,
               const MeshSaveOptions& options = {});

/// True if Assimp has an importer for this file's extension.
[[nodiscard]] bool is_mesh_file_supported(const std::filesystem::path& path);

/// Metres per unit for a length-unit name ("m", "cm", "mm", "um", "in", "ft"); nullopt if
/// unknown. For scene files that say which unit a mesh file is in.
[[nodiscard]] std::optional<double> metres_per_unit(std::string_view unit);

}  // namespace hapsim
