// CSG solids in scene files (seed 000 §3.1; docs/scene-format.md, "csg"): a geometry
//   {"csg": NODE, "resolution_m": 0.002}
// where NODE is exactly one of box, sphere, cylinder, cone, torus, union, intersection or
// difference (a list of at least two NODEs; difference: the first minus all the rest), each with
// an optional "pose" written as a body's. The solid itself answers contact (CsgQuery, exact
// signed distance); the polygonised mesh is for display, sphere trees and the content hash.
// Every error is a hapsim::Error at "<file>:<JSON pointer>" of the offending value.
#pragma once

#include "hapsim/core/progress.h"
#include "hapsim/geometry/csg.h"
#include "hapsim/geometry/triangle_mesh.h"
#include "hapsim/scene/json_reader.h"

#include <cstddef>
#include <string>

namespace hapsim {

/// Display-mesh cell size when a scene gives none, metres: finer than a fingertip, coarse enough
/// that a hand-sized solid polygonises in well under a second.
inline constexpr double kCsgDefaultResolutionM = 0.002;
/// Finest display-mesh cell a scene may ask for, metres.
inline constexpr double kCsgMinResolutionM = 1e-4;
/// Largest polygoniser grid (nodes) a scene may ask for: about 200³, a few seconds and ~100 MB
/// at load; a huge solid at a fine resolution is refused instead of asking for billions of cells.
inline constexpr std::size_t kCsgMaxGridNodes = 8'000'000;
/// Deepest nesting of NODEs, and most primitives in one solid: evaluation walks the whole tree
/// every haptic cycle, so its size is bounded (lists are combined as balanced trees, so the
/// evaluation depth grows with the logarithm of a list's length, not the length).
inline constexpr int kCsgMaxDepth = 32;
inline constexpr std::size_t kCsgMaxPrimitives = 256;

struct CsgGeometry {
  /// The solid, in the body frame (every node's pose applied).
  CsgSolid solid;
  /// Its polygonised surface, body frame: closed and outward-oriented.
  TriangleMesh mesh;
  /// The cell the mesh was polygonised at; the scene's own (requested_resolution_m) unless a
  /// grid node budget coarsened it.
  double resolution_m = kCsgDefaultResolutionM;
  double requested_resolution_m = kCsgDefaultResolutionM;
};

/// Reads one NODE at `ptr` into a solid in its parent's frame (the node's pose applied).
[[nodiscard]] CsgSolid read_csg_node(const JsonReader& reader, const JsonReader::Json& node,
                                     const std::string& ptr);

/// Reads a geometry object {"csg": NODE, "resolution_m": r} at `ptr` (the caller has checked
/// that it holds "csg") and polygonises the solid at r; with `grid_node_budget` > 0, at the
/// finest cell no finer than r whose grid has at most that many nodes (SceneDetailCaps).
[[nodiscard]] CsgGeometry read_csg_geometry(const JsonReader& reader,
                                            const JsonReader::Json& geometry,
                                            const std::string& ptr, const ProgressFn& progress = {},
                                            std::size_t grid_node_budget = 0);

}  // namespace hapsim
