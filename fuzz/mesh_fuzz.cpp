// Fuzz target: bytes as a mesh file through load_mesh (Assimp in its isolated child, then welding,
// validation and repair). The first byte picks the format: 0 STL (binary or ASCII: Assimp tells by
// the content), 1 OBJ, 2 PLY; the rest is the file. Checks: load_mesh returns a mesh whose
// triangles index its vertices, or throws hapsim::Error (a crash or hang inside Assimp included:
// that is the isolation's job); nothing else escapes.
#include "file_fuzz_support.h"
#include "hapsim/geometry/mesh_io.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  if (size < 1) {
    return 0;
  }
  static const char* const kNames[] = {"fuzz.stl", "fuzz.obj", "fuzz.ply"};
  const auto path =
      hapsim::fuzz::scratch_file(kNames[data[0] % 3], hapsim::fuzz::as_text(data + 1, size - 1));
  hapsim::MeshLoadOptions options;
  options.weld_tolerance_rel = 1e-6;
  hapsim::fuzz::expect_value_or_error([&] {
    const hapsim::TriangleMesh mesh = hapsim::load_mesh(path, options);
    for (const auto& t : mesh.triangles) {
      HAPSIM_FUZZ_CHECK(
          t[0] < mesh.vertices.size() && t[1] < mesh.vertices.size() && t[2] < mesh.vertices.size(),
          "a loaded mesh's triangles index its vertices");
    }
  });
  return 0;
}
