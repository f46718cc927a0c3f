// Fuzz target: our half of a mesh load, in process (finish_imported_mesh: what load_mesh does
// with the importer's triangles: scale, weld, validate, repair, normals). The mesh target runs
// the whole load, Assimp in a child process per input (a few inputs a second under the
// sanitizers); this one reaches the same code thousands of times a second. Layout:
//   byte 0: bit 0 weld; bits 1-2 the policy (default, strict, repair_all, warn_only); bits 3-4
//           the scale (1, 1e-3, -1, 1e3); bits 5-6 the relative weld tolerance (0, 1e-6, 1e-3,
//           0.5); bit 7 raw coordinates (8-byte doubles, NaN and infinities included) instead of
//           one signed byte per coordinate in millimetres (so vertices coincide and triangles
//           degenerate, as in an STL's soup)
//   byte 1: the vertex count n; then n vertices; then triangles, one byte per index taken modulo
//           n + 1 (so an index is in range or one past the end, as a corrupt file's may be).
// Checks: the mesh comes back or hapsim::Error is thrown; a returned mesh has no defect its
// policy refuses (validate_mesh again: out-of-range indices and non-finite vertices included
// wherever the policy refuses them, which every policy but warn_only does).
#include "file_fuzz_support.h"
#include "hapsim/geometry/mesh_io.h"

#include <cstring>

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  if (size < 2) {
    return 0;
  }
  const std::uint8_t flags = data[0];
  const std::size_t n = data[1];
  const bool raw = (flags & 0x80) != 0;
  const std::size_t vertex_bytes = n * 3 * (raw ? sizeof(double) : 1);
  if (size < 2 + vertex_bytes) {
    return 0;
  }
  hapsim::TriangleMesh soup;
  const std::uint8_t* p = data + 2;
  for (std::size_t i = 0; i < n; ++i) {
    hapsim::Vec3 v;
    for (int a = 0; a < 3; ++a) {
      if (raw) {
        std::memcpy(&v[a], p, sizeof(double));
        p += sizeof(double);
      } else {
        v[a] = 1e-3 * static_cast<std::int8_t>(*p++);
      }
    }
    soup.vertices.push_back(v);
  }
  for (; p + 3 <= data + size; p += 3) {
    soup.triangles.push_back({static_cast<std::uint32_t>(p[0] % (n + 1)),
                              static_cast<std::uint32_t>(p[1] % (n + 1)),
                              static_cast<std::uint32_t>(p[2] % (n + 1))});
  }
  static const hapsim::ValidationPolicy kPolicies[] = {
      hapsim::ValidationPolicy{}, hapsim::ValidationPolicy::strict(),
      hapsim::ValidationPolicy::repair_all(), hapsim::ValidationPolicy::warn_only()};
  static const double kScales[] = {1.0, 1e-3, -1.0, 1e3};
  static const double kTolerances[] = {0.0, 1e-6, 1e-3, 0.5};
  hapsim::MeshLoadOptions options;
  options.weld = (flags & 1) != 0;
  options.policy = kPolicies[(flags >> 1) & 3];
  options.scale = kScales[(flags >> 3) & 3];
  options.weld_tolerance_rel = kTolerances[(flags >> 5) & 3];
  hapsim::fuzz::expect_value_or_error([&] {
    const hapsim::TriangleMesh mesh =
        hapsim::finish_imported_mesh(std::move(soup), 0, "fuzz.soup", options);
    const hapsim::MeshReport after = hapsim::validate_mesh(mesh, options.validation);
    for (std::size_t d = 0; d < hapsim::kMeshDefectCount; ++d) {
      const auto defect = static_cast<hapsim::MeshDefect>(d);
      HAPSIM_FUZZ_CHECK(
          options.policy[defect] != hapsim::DefectAction::kRefuse || after.count(defect) == 0,
          "a loaded mesh has no defect its policy refuses");
    }
  });
  return 0;
}
