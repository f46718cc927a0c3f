// The detail the scene fuzz targets (scene, scene_step) let a scene generate; also loaded by
// tests/scene/scene_detail_caps_test.cpp, which checks the seeds still load whole under it.
#pragma once

#include "hapsim/scene/scene_file.h"

namespace hapsim::fuzz {

/// What the scene targets let a scene generate (SceneLoadOptions::detail_caps): every reader and
/// generator still runs, on a few thousand cells instead of up to millions, so an input takes
/// milliseconds under the sanitizers instead of a second (the knee at its own resolution, a CSG
/// solid at 1.5 mm) and a mutated resolution cannot make one take minutes. What finer detail
/// reaches (the same code on larger arrays) is the replays' and the tests' to check.
inline constexpr SceneDetailCaps kSceneDetailCaps{.csg_grid_nodes = 8000,
                                                  .knee_resolution_scale = 0.5,
                                                  .sphere_segments = 16,
                                                  .sheet_nodes_per_side = 16,
                                                  .tet_block_cells = 4};

}  // namespace hapsim::fuzz
