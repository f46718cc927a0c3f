// The Python module's parts (docs/python.md), one translation unit each so the module compiles in
// a few small pieces: errors and scenes, runs and recordings (module.cpp), the world and its
// step (world_binding.cpp), meshes and chains (geometry_binding.cpp), FEM bodies and tet meshes
// (fem_binding.cpp).
#pragma once

#include "hapsim/core/error.h"
#include "hapsim/scene/scene_description.h"

#include <pybind11/pybind11.h>

#include <memory>

namespace hapsim {
class World;
}  // namespace hapsim

namespace hapsim::python {

/// hapsim.Scene: a loaded scene file, shared by the worlds and runs built from it.
struct Scene {
  std::shared_ptr<const SceneDescription> description;
};

/// hapsim.Error (a ValueError) and hapsim.SceneError (an Error from loading a scene), each with
/// `where`, `file`, `pointer` and `detail`; hapsim::Error is translated to hapsim.Error.
void bind_errors(pybind11::module_& m);
/// Raises hapsim.SceneError for an error met while loading or assembling a scene.
[[noreturn]] void raise_scene_error(const Error& e);

void bind_world(pybind11::module_& m);
void bind_geometry(pybind11::module_& m);
/// hapsim.TetMesh, read_tet_mesh, make_tet_block, tet_mesh_quality, and World's fem_* methods
/// (added to the class bind_world made: call it after bind_world).
void bind_fem(pybind11::module_& m);

/// The world of a hapsim.World object (world_binding.cpp; raises TypeError for anything else).
[[nodiscard]] const World& world_of(const pybind11::handle& py_world);

}  // namespace hapsim::python
