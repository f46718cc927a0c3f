// Fuzz target: bytes as a tetrahedral mesh file (geometry/tet_mesh_io.h). The first byte picks
// the reader: 0 Gmsh MSH 4.1 (parse_gmsh_msh4), 1 TetGen (parse_tetgen: the .node text, a NUL
// byte, then the .ele text), 2 legacy VTK (parse_vtk_unstructured). Checks: a returned mesh is
// valid as validate_tet_mesh defines it (indices in range, finite nodes, every tet positively
// oriented and not flat, one piece, one region per tet or none), and its boundary, quality and an
// embedding of its nodes work on it; or the reader throws hapsim::Error. Nothing else escapes.
#include "file_fuzz_support.h"
#include "hapsim/geometry/tet_embedding.h"
#include "hapsim/geometry/tet_mesh_io.h"

#include <cmath>
#include <string_view>

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  if (size < 1) {
    return 0;
  }
  const int reader = data[0] % 3;
  const std::string_view text = hapsim::fuzz::as_text(data + 1, size - 1);
  hapsim::fuzz::expect_value_or_error([&] {
    hapsim::TetMesh mesh;
    if (reader == 0) {
      mesh = hapsim::parse_gmsh_msh4(text, "fuzz.msh");
    } else if (reader == 1) {
      const std::size_t split = text.find('\0');
      const std::string_view node = text.substr(0, split);
      const std::string_view ele =
          split == std::string_view::npos ? std::string_view() : text.substr(split + 1);
      mesh = hapsim::parse_tetgen(node, ele, "fuzz");
    } else {
      mesh = hapsim::parse_vtk_unstructured(text, "fuzz.vtk");
    }
    HAPSIM_FUZZ_CHECK(!hapsim::find_tet_mesh_problem(mesh).has_value(), "a read mesh is valid");
    HAPSIM_FUZZ_CHECK(mesh.regions.empty() || mesh.regions.size() == mesh.tets.size(),
                      "one region per tet");
    for (std::size_t t = 0; t < mesh.tet_count(); ++t) {
      HAPSIM_FUZZ_CHECK(mesh.signed_volume(t) > 0.0, "every tet positively oriented");
    }
    const hapsim::TetMeshQuality q = hapsim::tet_mesh_quality(mesh);
    HAPSIM_FUZZ_CHECK(q.inverted == 0 && q.degenerate == 0 && q.components == 1,
                      "quality agrees with validation");
    HAPSIM_FUZZ_CHECK(std::isfinite(q.max_aspect_ratio) && q.min_dihedral_deg >= 0.0,
                      "quality is finite");
    const hapsim::TetBoundary b = hapsim::tet_boundary(mesh);
    HAPSIM_FUZZ_CHECK(b.surface.triangle_count() >= 4, "a valid mesh has a boundary");
    // Its own nodes embed at distance zero (each is a corner of a tet that uses it).
    const std::vector<hapsim::TetEmbedding> e = hapsim::embed_points(mesh, mesh.nodes);
    for (std::size_t i = 0; i < e.size(); ++i) {
      HAPSIM_FUZZ_CHECK(e[i].tet < mesh.tet_count(), "an embedding names a tet");
      HAPSIM_FUZZ_CHECK(std::isfinite(e[i].distance_m), "an embedding is finite");
    }
  });
  return 0;
}
