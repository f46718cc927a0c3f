// A body's "geometry" in a scene file (docs/scene-format.md, "Geometry kinds") turned into its
// segments: the procedural knee (one segment per part, each with its tissue), a box, a sphere, a
// sheet, a mesh file, a folder of mesh files (one segment each), or a CSG solid (csg_reader.h).
// Every error is a hapsim::Error at "<file>:<JSON pointer>" of the offending value.
#pragma once

#include "hapsim/geometry/procedural_knee.h"
#include "hapsim/geometry/tet_mesh.h"
#include "hapsim/scene/scene_reader.h"
#include "hapsim/world/world_description.h"

#include <filesystem>
#include <memory>
#include <optional>
#include <set>
#include <string>
#include <vector>

namespace hapsim {

/// The segments a geometry gives (name, mesh, two-sidedness, CSG solid; no material yet) and,
/// per segment, its tissue where the geometry knows it (the procedural knee), for the body's
/// "by_tissue" material rules.
struct BodyGeometry {
  std::vector<SegmentDescription> segments;
  std::vector<std::optional<TissueKind>> tissues;
  /// A volume ("tet_block", "tet_mesh"): its tetrahedra (body frame), whether the one segment's
  /// mesh is a finer surface embedded in them (else their boundary), and where it came from.
  std::shared_ptr<const TetMesh> tets;
  bool embedded_surface = false;
  std::string tets_source;
};

/// Reads the geometries of one scene's bodies, and collects its warnings: a mesh file whose size
/// at its "scale" is implausible for a body part (check_body_part_size, body_part_size.h) gets
/// one, naming the file and the scale that would fix it, however many bodies use the file; the
/// files of one mesh_folder that one scale would fix share one.
class GeometryReader {
 public:
  explicit GeometryReader(const SceneReader& reader) : r_(reader) {}

  /// Reads the geometry object `j` at `ptr` of the body called `body_name` (single shapes give
  /// one segment named after the body).
  [[nodiscard]] BodyGeometry read(const JsonReader::Json& j, const std::string& ptr,
                                  const std::string& body_name);

  /// The warnings so far, in the order found: "<scene file>:<JSON pointer>: <what>".
  [[nodiscard]] const std::vector<std::string>& warnings() const { return warnings_; }

 private:
  struct LoadedMesh {
    std::filesystem::path file;
    const TriangleMesh* mesh = nullptr;
  };
  /// Checks the sizes of the meshes loaded at `ptr` (a mesh, or a mesh_folder's `folder`).
  void check_sizes(const std::string& ptr, const std::vector<LoadedMesh>& meshes, double scale,
                   const std::filesystem::path& folder);

  /// The "tet_block" / "tet_mesh" geometry at `kp` into `body`.
  void read_tets(const JsonReader::Json& j, const std::string& kp, const std::string& kind,
                 const std::string& body_name, BodyGeometry& body);

  /// `value`, or `cap` (SceneDetailCaps; 0: none) when larger, with a warning naming `ptr`.
  double capped(double value, double cap, const std::string& ptr);

  const SceneReader& r_;
  std::set<std::filesystem::path> size_checked_;
  std::vector<std::string> warnings_;
};

}  // namespace hapsim
