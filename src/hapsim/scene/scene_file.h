// Reading scene files ("format": "hapsim-scene/1", docs/scene-format.md, scenes/scene.schema.json)
// into a SceneDescription: materials, bodies and their geometry (procedural knee, box, sphere,
// sheet, a mesh file, a folder of mesh files (one segment each), a CSG solid, or a FEM body's
// volume: a tet_block or tet_mesh with its "fem" settings in fem_reader.h), tools, the
// device and the run, and a robot "rig" beside them. This file reads the top level, materials,
// bodies, tools and run; the parts have their own readers on the same SceneReader
// (scene_reader.h: JSON pointers in errors, paths): geometry_reader.h (a body's geometry into
// segments; CSG solids in csg_reader.h), device_reader.h (the device, palpation and glove
// palpation scripts, a rig's master), rig_reader.h (the rig) and teleop_dialect.h (the older
// "teleop" files, converted on read with a note).
// Every error is a hapsim::Error whose where() is "<file>:<JSON pointer>" and whose message
// says what was expected; unknown keys are errors; a load either returns a complete description
// or throws (nothing half-loads).
#pragma once

#include "hapsim/core/progress.h"
#include "hapsim/scene/scene_description.h"

#include <cstddef>
#include <filesystem>
#include <string_view>

namespace hapsim {

/// Caps on the detail the loader generates, for tools that load many scenes and look at none
/// (the fuzz targets, fuzz/scene_fuzz.cpp: a million loads under a sanitizer). A scene asking for
/// finer detail gets the cap instead, said once per value in SceneDescription::warnings; every
/// reader and generator still runs, on less. Zero: no cap (the default: the scene's own values,
/// within the limits of docs/scene-format.md).
struct SceneDetailCaps {
  /// Polygoniser grid nodes for one CSG solid's display mesh: a finer resolution_m is coarsened
  /// until the grid fits (a scene beyond kCsgMaxGridNodes is still refused, as without caps).
  std::size_t csg_grid_nodes = 0;
  /// The procedural knee's resolution_scale: a larger one is lowered to this.
  double knee_resolution_scale = 0.0;
  /// A sphere's segments around (and half as many rings): more are lowered to this.
  int sphere_segments = 0;
  /// A sheet's nodes per side: more are lowered to this.
  int sheet_nodes_per_side = 0;
  /// A tet_block's cells along each axis: more are lowered to this (a FEM body factors its
  /// system when the world is built: seconds for 80k tets).
  int tet_block_cells = 0;
};

struct SceneLoadOptions {
  /// The scene's data folder: paths written "data:REL" resolve against it. Empty: the scene's
  /// "data" default folder under the hapsim data root ($HAPSIM_DATA, else ../shared/data beside
  /// the checkout that holds the scene).
  std::filesystem::path data_dir;
  /// Progress while loading meshes and generating geometry. May be empty.
  ProgressFn progress;
  /// Detail caps (none by default).
  SceneDetailCaps detail_caps;
  /// False when the command plays its own trajectory (`--device sim:FILE`): the device's
  /// "trajectory" file is then not needed, its path kept unchecked.
  bool device_trajectory_played = true;
};

/// Reads and parses `file`. Relative paths in the scene resolve against the file's folder.
[[nodiscard]] SceneDescription load_scene(const std::filesystem::path& file,
                                          const SceneLoadOptions& options = {});

/// Parses scene JSON text; `file` names it in errors and anchors relative paths.
[[nodiscard]] SceneDescription parse_scene(std::string_view json_text,
                                           const std::filesystem::path& file,
                                           const SceneLoadOptions& options = {});

}  // namespace hapsim
