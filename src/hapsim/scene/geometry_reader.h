// A body's "geometry" in a scene file (docs/scene-format.md, "Geometry kinds") turned into its
// segments: the procedural knee (one segment per part, each with its tissue), a box, a sphere, a
// sheet, a mesh file, a folder of mesh files (one segment each), or a CSG solid (csg_reader.h).
// Every error is a hapsim::Error at "<file>:<JSON pointer>" of the offending value.
#pragma once

#include "hapsim/geometry/procedural_knee.h"
#include "hapsim/scene/scene_reader.h"
#include "hapsim/world/world_description.h"

#include <optional>
#include <string>
#include <vector>

namespace hapsim {

/// The segments a geometry gives (name, mesh, two-sidedness, CSG solid; no material yet) and,
/// per segment, its tissue where the geometry knows it (the procedural knee), for the body's
/// "by_tissue" material rules.
struct BodyGeometry {
  std::vector<SegmentDescription> segments;
  std::vector<std::optional<TissueKind>> tissues;
};

class GeometryReader {
 public:
  explicit GeometryReader(const SceneReader& reader) : r_(reader) {}

  /// Reads the geometry object `j` at `ptr` of the body called `body_name` (single shapes give
  /// one segment named after the body).
  [[nodiscard]] BodyGeometry read(const JsonReader::Json& j, const std::string& ptr,
                                  const std::string& body_name);

 private:
  const SceneReader& r_;
};

}  // namespace hapsim
