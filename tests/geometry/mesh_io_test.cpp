// Mesh loading through Assimp against small files written here by hand (so the loader is checked
// against independent content), corrupt files, and the real knee and robot data when present.
#include "hapsim/geometry/mesh_io.h"
#include "hapsim/core/data_dir.h"
#include "hapsim/core/error.h"
#include "hapsim/geometry/procedural.h"
#include "support/test_data.h"

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <cstring>
#include <fstream>
#include <random>
#include <sstream>
#include <string>
#include <vector>

namespace hapsim {
namespace {

namespace fs = std::filesystem;

class MeshIo : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() /
           ("hapsim_mesh_io_" + std::to_string(::testing::UnitTest::GetInstance()->random_seed()) +
            "_" + ::testing::UnitTest::GetInstance()->current_test_info()->name());
    fs::create_directories(dir_);
  }
  void TearDown() override {
    std::error_code ec;
    fs::remove_all(dir_, ec);
  }
  fs::path write(const std::string& name, const std::string& bytes) const {
    const fs::path p = dir_ / name;
    std::ofstream(p, std::ios::binary) << bytes;
    return p;
  }
  fs::path dir_;
};

// The unit cube [0,1]³ as an OBJ with quads (1-based indices, counter-clockwise from outside).
constexpr const char* kCubeObj = R"(# unit cube
v 0 0 0
v 1 0 0
v 0 1 0
v 1 1 0
v 0 0 1
v 1 0 1
v 0 1 1
v 1 1 1
f 1 3 4 2
f 5 6 8 7
f 1 2 6 5
f 3 7 8 4
f 1 5 7 3
f 2 4 8 6
)";

// Regular-ish tetrahedron (0,0,0),(1,0,0),(0,1,0),(0,0,1), outward faces; volume 1/6.
const std::vector<Vec3> kTetVertices = {Vec3(0, 0, 0), Vec3(1, 0, 0), Vec3(0, 1, 0), Vec3(0, 0, 1)};
const std::vector<TriangleIndices> kTetFaces = {{0, 2, 1}, {0, 1, 3}, {0, 3, 2}, {1, 2, 3}};

std::string ascii_stl(double unit = 1.0) {
  std::ostringstream s;
  s << "solid tet\n";
  for (const auto& f : kTetFaces) {
    s << "  facet normal 0 0 0\n    outer loop\n";
    for (auto v : f) {
      const Vec3 p = unit * kTetVertices[v];
      s << "      vertex " << p.x() << " " << p.y() << " " << p.z() << "\n";
    }
    s << "    endloop\n  endfacet\n";
  }
  s << "endsolid tet\n";
  return s.str();
}

void put_u32(std::string& out, std::uint32_t v) {
  char b[4];
  std::memcpy(b, &v, 4);  // the tests run on little-endian hosts, as STL is
  out.append(b, 4);
}
void put_f32(std::string& out, float v) {
  char b[4];
  std::memcpy(b, &v, 4);
  out.append(b, 4);
}

// Binary STL of the tetrahedron; `claimed_count` overrides the header's facet count.
std::string binary_stl(std::int64_t claimed_count = -1) {
  std::string out(80, ' ');
  out.replace(0, 16, "binary tet hdr  ");  // must not start with "solid"
  put_u32(out, claimed_count < 0 ? static_cast<std::uint32_t>(kTetFaces.size())
                                 : static_cast<std::uint32_t>(claimed_count));
  for (const auto& f : kTetFaces) {
    for (int k = 0; k < 3; ++k) {
      put_f32(out, 0.0f);  // normal: unused by the loader
    }
    for (auto v : f) {
      for (int k = 0; k < 3; ++k) {
        put_f32(out, static_cast<float>(kTetVertices[v][k]));
      }
    }
    out.append(2, '\0');  // attribute byte count
  }
  return out;
}

std::string base64(const std::string& bytes) {
  static constexpr char kAlphabet[] =
      "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
  std::string out;
  std::size_t i = 0;
  for (; i + 2 < bytes.size(); i += 3) {
    const auto n = (static_cast<unsigned char>(bytes[i]) << 16) |
                   (static_cast<unsigned char>(bytes[i + 1]) << 8) |
                   static_cast<unsigned char>(bytes[i + 2]);
    out += {kAlphabet[(n >> 18) & 63], kAlphabet[(n >> 12) & 63], kAlphabet[(n >> 6) & 63],
            kAlphabet[n & 63]};
  }
  if (i + 1 == bytes.size()) {
    const auto n = static_cast<unsigned char>(bytes[i]) << 16;
    out += {kAlphabet[(n >> 18) & 63], kAlphabet[(n >> 12) & 63], '=', '='};
  } else if (i + 2 == bytes.size()) {
    const auto n = (static_cast<unsigned char>(bytes[i]) << 16) |
                   (static_cast<unsigned char>(bytes[i + 1]) << 8);
    out += {kAlphabet[(n >> 18) & 63], kAlphabet[(n >> 12) & 63], kAlphabet[(n >> 6) & 63], '='};
  }
  return out;
}

// glTF 2.0 with an embedded base64 buffer: the tetrahedron instanced twice — under a parent
// translated by (1,2,3) with the child scaled ×2, and once mirrored (scale −1 in x) at x = 10.
std::string tet_gltf() {
  std::string buffer;
  for (const Vec3& v : kTetVertices) {
    for (int k = 0; k < 3; ++k) {
      put_f32(buffer, static_cast<float>(v[k]));
    }
  }
  for (const auto& f : kTetFaces) {
    for (auto v : f) {
      const auto i = static_cast<std::uint16_t>(v);
      buffer.append(reinterpret_cast<const char*>(&i), 2);
    }
  }
  nlohmann::json j = {
      {"asset", {{"version", "2.0"}}},
      {"scene", 0},
      {"scenes", {{{"nodes", {0, 2}}}}},
      {"nodes",
       {{{"translation", {1.0, 2.0, 3.0}}, {"children", {1}}},
        {{"mesh", 0}, {"scale", {2.0, 2.0, 2.0}}},
        {{"mesh", 0}, {"translation", {10.0, 0.0, 0.0}}, {"scale", {-1.0, 1.0, 1.0}}}}},
      {"meshes", {{{"primitives", {{{"attributes", {{"POSITION", 0}}}, {"indices", 1}}}}}}},
      {"buffers",
       {{{"uri", "data:application/octet-stream;base64," + base64(buffer)},
         {"byteLength", buffer.size()}}}},
      {"bufferViews",
       {{{"buffer", 0}, {"byteOffset", 0}, {"byteLength", 48}, {"target", 34962}},
        {{"buffer", 0}, {"byteOffset", 48}, {"byteLength", 24}, {"target", 34963}}}},
      {"accessors",
       {{{"bufferView", 0},
         {"componentType", 5126},
         {"count", 4},
         {"type", "VEC3"},
         {"min", {0.0, 0.0, 0.0}},
         {"max", {1.0, 1.0, 1.0}}},
        {{"bufferView", 1}, {"componentType", 5123}, {"count", 12}, {"type", "SCALAR"}}}}};
  return j.dump(1);
}

void expect_unit_cube(const TriangleMesh& m) {
  EXPECT_EQ(m.vertex_count(), 8u);
  EXPECT_EQ(m.triangle_count(), 12u);
  EXPECT_NEAR(m.signed_volume(), 1.0, 1e-6);
  EXPECT_NEAR(m.surface_area(), 6.0, 1e-6);
  EXPECT_EQ(m.vertex_normals.size(), 8u);
  const MeshReport r = validate_mesh(m);
  EXPECT_TRUE(r.closed) << r.summary();
  EXPECT_FALSE(r.has_defects()) << r.summary();
}

void expect_tet(const TriangleMesh& m, double unit_m) {
  EXPECT_EQ(m.vertex_count(), 4u);
  EXPECT_EQ(m.triangle_count(), 4u);
  EXPECT_NEAR(m.signed_volume(), unit_m * unit_m * unit_m / 6.0, 1e-7 * unit_m * unit_m * unit_m);
  const MeshReport r = validate_mesh(m);
  EXPECT_TRUE(r.closed) << r.summary();
  EXPECT_FALSE(r.has_defects()) << r.summary();
}

// Expects load_mesh to throw an Error that names the file.
void expect_refused(const fs::path& path, const MeshLoadOptions& options = {},
                    const std::string& fragment = "") {
  try {
    (void)load_mesh(path, options);
    ADD_FAILURE() << "expected an Error for " << path;
  } catch (const Error& e) {
    EXPECT_EQ(e.where(), path.string());
    EXPECT_NE(std::string(e.what()).find(path.filename().string()), std::string::npos);
    if (!fragment.empty()) {
      EXPECT_NE(std::string(e.what()).find(fragment), std::string::npos) << e.what();
    }
  }
}

TEST_F(MeshIo, ObjQuadsAreTriangulatedAndWelded) {
  MeshReport report;
  const TriangleMesh m = load_mesh(write("cube.obj", kCubeObj), {}, &report);
  expect_unit_cube(m);
  EXPECT_TRUE(report.closed);
  EXPECT_TRUE(report.notes.empty());
}

TEST_F(MeshIo, AsciiStlIsWeldedAndScaledToMetres) {
  MeshLoadOptions mm;
  mm.scale = 1e-3;
  const TriangleMesh m = load_mesh(write("tet.stl", ascii_stl(50.0)), mm);  // 50 mm edges
  expect_tet(m, 0.05);
  EXPECT_NEAR(m.bounds().max().x(), 0.05, 1e-9);
}

TEST_F(MeshIo, BinaryStl) {
  expect_tet(load_mesh(write("tet_bin.stl", binary_stl())), 1.0);
  // Without welding the soup stays 12 separate corners: every edge is open.
  MeshLoadOptions no_weld;
  no_weld.weld = false;
  MeshReport report;
  const TriangleMesh soup = load_mesh(write("tet_bin2.stl", binary_stl()), no_weld, &report);
  EXPECT_EQ(soup.triangle_count(), 4u);
  // Assimp's JoinIdenticalVertices still shares corners identical in every attribute.
  EXPECT_LE(report.vertex_count, 12u);
  EXPECT_GE(report.vertex_count, 4u);
}

TEST_F(MeshIo, AsciiPly) {
  const std::string ply =
      "ply\nformat ascii 1.0\nelement vertex 8\nproperty float x\nproperty float y\n"
      "property float z\nelement face 6\nproperty list uchar int vertex_indices\nend_header\n"
      "0 0 0\n1 0 0\n0 1 0\n1 1 0\n0 0 1\n1 0 1\n0 1 1\n1 1 1\n"
      "4 0 2 3 1\n4 4 5 7 6\n4 0 1 5 4\n4 2 6 7 3\n4 0 4 6 2\n4 1 3 7 5\n";
  expect_unit_cube(load_mesh(write("cube.ply", ply)));
}

TEST_F(MeshIo, GltfWithEmbeddedBufferAppliesNodeTransforms) {
  MeshReport report;
  const TriangleMesh m = load_mesh(write("tets.gltf", tet_gltf()), {}, &report);
  EXPECT_EQ(m.triangle_count(), 8u);
  EXPECT_EQ(m.vertex_count(), 8u);
  EXPECT_EQ(report.components, 2u);
  EXPECT_TRUE(report.closed) << report.summary();
  EXPECT_EQ(report.inverted_components, 0u);  // the mirrored instance keeps outward winding
  EXPECT_NEAR(m.signed_volume(), 8.0 / 6.0 + 1.0 / 6.0, 1e-6);
  const Box3 b = m.bounds();
  EXPECT_TRUE(b.min().isApprox(Vec3(1, 0, 0), 1e-6)) << b.min().transpose();
  EXPECT_TRUE(b.max().isApprox(Vec3(10, 4, 5), 1e-6)) << b.max().transpose();
}

TEST_F(MeshIo, WeldToleranceClosesNearlyCoincidentVertices) {
  // ASCII STL whose repeated corners differ in the 7th digit (as exporters with rounding do).
  std::string stl = ascii_stl(1.0);
  const std::size_t at = stl.find("vertex 1 0 0", stl.find("vertex 1 0 0") + 1);
  ASSERT_NE(at, std::string::npos);
  stl.replace(at, 12, "vertex 1.000001 0 0");
  const fs::path p = write("jitter.stl", stl);
  MeshReport exact;
  (void)load_mesh(p, {}, &exact);
  EXPECT_GT(exact.open_edges, 0u);
  MeshLoadOptions tol;
  tol.weld_tolerance_rel = 1e-5;
  MeshReport welded;
  const TriangleMesh m = load_mesh(p, tol, &welded);
  EXPECT_TRUE(welded.closed) << welded.summary();
  EXPECT_EQ(m.vertex_count(), 4u);
}

TEST_F(MeshIo, PolicyWarnsRepairsOrRefuses) {
  // An inside-out cube with a degenerate face and a stray vertex.
  const std::string obj =
      std::string(kCubeObj).replace(std::string(kCubeObj).find("f 1 3 4 2"), 9, "f 1 2 4 3") +
      "v 5 5 5\nf 1 1 2\n";
  // Only the first face is flipped above: make all of them inward instead.
  std::string inward = "# inside-out cube\n";
  std::istringstream lines(kCubeObj);
  for (std::string line; std::getline(lines, line);) {
    if (line.rfind("f ", 0) == 0) {
      std::istringstream f(line.substr(2));
      int a, b, c, d;
      f >> a >> b >> c >> d;
      inward += "f " + std::to_string(d) + " " + std::to_string(c) + " " + std::to_string(b) + " " +
                std::to_string(a) + "\n";
    } else {
      inward += line + "\n";
    }
  }
  const fs::path p = write("inside_out.obj", inward);
  MeshReport report;
  const TriangleMesh fixed = load_mesh(p, {}, &report);  // default: flip with a warning
  EXPECT_EQ(report.inverted_components, 1u);
  ASSERT_FALSE(report.notes.empty());
  EXPECT_NE(report.to_json().find("inverted_components"), std::string::npos);
  EXPECT_NEAR(fixed.signed_volume(), 1.0, 1e-6);

  MeshLoadOptions warn;
  warn.policy[MeshDefect::kInvertedComponent] = DefectAction::kWarn;
  EXPECT_NEAR(load_mesh(p, warn).signed_volume(), -1.0, 1e-6);

  MeshLoadOptions strict;
  strict.policy = ValidationPolicy::strict();
  expect_refused(p, strict, "inverted_components=1");

  // Open mesh: accepted with a warning by default, refused by strict.
  const fs::path open =
      write("open.obj", std::string(kCubeObj).substr(0, std::string(kCubeObj).rfind("f ")));
  MeshReport open_report;
  const TriangleMesh open_mesh = load_mesh(open, {}, &open_report);
  EXPECT_EQ(open_mesh.triangle_count(), 10u);
  EXPECT_EQ(open_report.open_edges, 4u);
  EXPECT_FALSE(open_report.closed);
  expect_refused(open, strict, "open_edges=4");
  (void)obj;
}

TEST_F(MeshIo, DegenerateAndDuplicateFacetsAreCountedThenDropped) {
  // The tetrahedron plus a facet with a repeated corner, a collinear facet and a repeated facet.
  std::string stl = ascii_stl(1.0);
  const std::string extra =
      "  facet normal 0 0 0\n    outer loop\n      vertex 0 0 0\n      vertex 0 0 0\n"
      "      vertex 1 0 0\n    endloop\n  endfacet\n"
      "  facet normal 0 0 0\n    outer loop\n      vertex 0 0 0\n      vertex 0.5 0 0\n"
      "      vertex 1 0 0\n    endloop\n  endfacet\n"
      "  facet normal 0 0 0\n    outer loop\n      vertex 1 0 0\n      vertex 0 1 0\n"
      "      vertex 0 0 1\n    endloop\n  endfacet\n";
  stl.insert(stl.find("endsolid"), extra);
  const fs::path p = write("dirty.stl", stl);
  MeshReport report;
  const TriangleMesh m = load_mesh(p, {}, &report);
  EXPECT_EQ(report.triangle_count, 7u);
  EXPECT_EQ(report.degenerate_triangles, 2u);
  EXPECT_EQ(report.duplicate_triangles, 1u);
  // Counted once, under their own names: no open or non-manifold edges from the sliver.
  EXPECT_EQ(report.open_edges, 0u);
  EXPECT_EQ(report.non_manifold_edges, 0u);
  EXPECT_FALSE(report.closed);  // not yet: the duplicate would count its volume twice
  EXPECT_EQ(report.notes.size(), 3u) << report.to_json(1);  // two defects + the repair line
  expect_tet(m, 1.0);                                       // dropped back to the clean tetrahedron
  MeshLoadOptions strict;
  strict.policy = ValidationPolicy::strict();
  expect_refused(p, strict, "degenerate_triangles=2");
}

TEST_F(MeshIo, NonFiniteCoordinatesAreRefusedOrReported) {
  // What Assimp makes of "nan"/"inf" text varies by importer; either the importer refuses the
  // file, or validation sees the non-finite vertex and the default policy refuses it.
  for (const char* bad : {"nan", "inf", "-inf", "1e999"}) {
    const std::string obj = std::string(kCubeObj).replace(std::string(kCubeObj).find("v 1 1 1"), 7,
                                                          std::string("v 1 ") + bad + " 1");
    const fs::path p = write(std::string("bad_") + (bad[0] == '-' ? "minf" : bad) + ".obj", obj);
    expect_refused(p);
    MeshLoadOptions lenient;
    lenient.policy = ValidationPolicy::warn_only();
    try {
      MeshReport report;
      const TriangleMesh m = load_mesh(p, lenient, &report);
      EXPECT_EQ(report.non_finite_vertices, 1u) << bad << ": " << report.summary();
    } catch (const Error& e) {
      EXPECT_EQ(e.where(), p.string());
    }
  }
  const std::string stl =
      ascii_stl(1.0).replace(ascii_stl(1.0).find("vertex 1 0 0"), 12, "vertex nan 0 0");
  expect_refused(write("nan.stl", stl));
}

TEST_F(MeshIo, CorruptFilesGiveErrorsNamingTheFile) {
  expect_refused(dir_ / "missing.obj", {}, "not found");
  expect_refused(write("empty.stl", ""), {}, "empty");
  expect_refused(write("mesh.notamesh", kCubeObj), {}, "unsupported");
  expect_refused(dir_, {});  // a directory
  // Binary STL whose facet count header lies (more facets than bytes), or is zero.
  expect_refused(write("lying_count.stl", binary_stl(1000)));
  expect_refused(write("huge_count.stl", binary_stl(0xFFFFFFFFll)));
  expect_refused(write("zero_count.stl", binary_stl(0)));
  // Truncated binary STL.
  const std::string bin = binary_stl();
  expect_refused(write("truncated.stl", bin.substr(0, 84 + 50 + 20)));
  expect_refused(write("header_only.stl", bin.substr(0, 40)));
  // Random garbage under mesh extensions.
  std::mt19937 rng(99);
  std::string garbage(300, '\0');
  for (char& c : garbage) {
    c = static_cast<char>(rng() & 0xFF);
  }
  for (const char* ext : {".stl", ".obj", ".ply", ".gltf", ".glb"}) {
    expect_refused(write(std::string("garbage") + ext, garbage));
  }
  expect_refused(write("text.obj", "hello world\nthis is not a mesh\n"));
  expect_refused(write("lines_only.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nl 1 2\nl 2 3\n"));
  expect_refused(write("bad_index.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 99\n"));
  expect_refused(write("truncated_ascii.stl",
                       "solid x\n facet normal 0 0 1\n  outer loop\n   vertex 0 0 0\n   vertex 1"));
  expect_refused(write("truncated.ply",
                       "ply\nformat ascii 1.0\nelement vertex 8\nproperty float x\nproperty float "
                       "y\nproperty float z\nelement face 6\nproperty list uchar int "
                       "vertex_indices\nend_header\n0 0 0\n1 0 0\n"));
  expect_refused(write("broken.gltf", tet_gltf().substr(0, 200)));
  std::string bad_scale = kCubeObj;
  MeshLoadOptions zero_scale;
  zero_scale.scale = 0.0;
  expect_refused(write("cube2.obj", bad_scale), zero_scale, "scale");
}

TEST_F(MeshIo, BinaryStlWithShortCountLoadsOnlyWhatItClaims) {
  // The header claims 2 of the 4 facets: the rest is trailing bytes. Assimp 5.2 refuses the
  // size mismatch; another version may read 2 facets. Either is fine: an Error naming the file
  // or an open mesh reported as such, never a crash.
  const fs::path p = write("short_count.stl", binary_stl(2));
  try {
    MeshReport report;
    const TriangleMesh m = load_mesh(p, {}, &report);
    EXPECT_LE(m.triangle_count(), 4u);
    if (m.triangle_count() < 4) {
      EXPECT_FALSE(report.closed);
      EXPECT_GT(report.open_edges, 0u);
    }
  } catch (const Error& e) {
    EXPECT_EQ(e.where(), p.string());
  }
}

TEST_F(MeshIo, SaveAndReloadRoundTrip) {
  const TriangleMesh sphere = make_uv_sphere(0.05, 32, 16);
  for (const char* name : {"s.stl", "s.obj", "s.ply", "s.glb"}) {
    for (bool binary : {true, false}) {
      MeshSaveOptions save;
      save.binary = binary;
      save.scale = 1e3;  // write millimetres
      const fs::path p = dir_ / name;
      save_mesh(p, sphere, save);
      MeshLoadOptions load;
      load.scale = 1e-3;
      MeshReport report;
      const TriangleMesh back = load_mesh(p, load, &report);
      EXPECT_EQ(back.vertex_count(), sphere.vertex_count()) << name;
      EXPECT_EQ(back.triangle_count(), sphere.triangle_count()) << name;
      EXPECT_NEAR(back.signed_volume(), sphere.signed_volume(), 1e-6 * sphere.signed_volume())
          << name;
      EXPECT_TRUE(report.closed) << name << ": " << report.summary();
    }
  }
  TriangleMesh bad = sphere;
  bad.triangles.push_back({0, 1, 100000});
  EXPECT_THROW(save_mesh(dir_ / "bad.stl", bad), Error);
  EXPECT_THROW(save_mesh(dir_ / "x.abc", sphere), Error);
  EXPECT_THROW(save_mesh(dir_ / "empty.stl", TriangleMesh{}), Error);
}

TEST(MeshIoUnits, MetresPerUnit) {
  EXPECT_EQ(metres_per_unit("mm"), 1e-3);
  EXPECT_EQ(metres_per_unit("M"), 1.0);
  EXPECT_EQ(metres_per_unit("in"), 0.0254);
  EXPECT_FALSE(metres_per_unit("furlong").has_value());
  EXPECT_TRUE(is_mesh_file_supported("a.STL"));
  EXPECT_TRUE(is_mesh_file_supported("a.gltf"));
  EXPECT_FALSE(is_mesh_file_supported("a.notamesh"));
}

// ---- real data (skipped when ../shared/data is absent) ----

TEST(MeshIoRealData, KneeStlsMatchPublishedStats) {
  const auto data = test::data_dir();
  HAPSIM_SKIP_WITHOUT_DATA(data && fs::exists(*data / "knee_vhf_left/mesh_stats.jsonl"),
                           "real knee mesh statistics not found");
  std::ifstream stats_file(*data / "knee_vhf_left/mesh_stats.jsonl");
  int files = 0;
  std::size_t total_vertices = 0;
  for (std::string line; std::getline(stats_file, line);) {
    if (line.empty()) {
      continue;
    }
    const auto s = nlohmann::json::parse(line);
    const fs::path p = *data / "knee_vhf_left/stl" / s["file"].get<std::string>();
    SCOPED_TRACE(p.filename().string());
    MeshLoadOptions mm;
    mm.scale = 1e-3;
    mm.policy = ValidationPolicy::strict();  // the data is documented closed and clean
    MeshReport r;
    const TriangleMesh m = load_mesh(p, mm, &r);
    ++files;
    total_vertices += m.vertex_count();
    EXPECT_EQ(r.vertex_count, s["welded_verts"].get<std::size_t>());
    EXPECT_EQ(r.triangle_count, s["tris"].get<std::size_t>());
    EXPECT_EQ(r.degenerate_triangles, s["degenerate"].get<std::size_t>());
    EXPECT_EQ(r.edge_count, s["edges"].get<std::size_t>());
    EXPECT_EQ(r.open_edges, s["boundary_edges"].get<std::size_t>());
    EXPECT_EQ(r.non_manifold_edges, s["nonmanifold_edges"].get<std::size_t>());
    EXPECT_EQ(r.components, s["components"].get<std::size_t>());
    EXPECT_EQ(r.euler_characteristic, s["euler"].get<long long>());
    EXPECT_EQ(r.inconsistent_edges == 0, s["consistently_oriented"].get<bool>());
    EXPECT_EQ(r.closed, s["watertight"].get<bool>());
    const double volume_m3 = s["signed_volume"].get<double>() * 1e-9;
    EXPECT_NEAR(r.signed_volume, volume_m3, 1e-6 * std::abs(volume_m3));
    for (int k = 0; k < 3; ++k) {
      EXPECT_NEAR(r.bounds.min()[k], s["bbox_min"][k].get<double>() * 1e-3, 1e-7);
      EXPECT_NEAR(r.bounds.max()[k], s["bbox_max"][k].get<double>() * 1e-3, 1e-7);
    }
    EXPECT_EQ(m.vertex_count(), r.vertex_count);
    EXPECT_EQ(m.vertex_normals.size(), m.vertex_count());
    EXPECT_GT(m.signed_volume(), 0.0);
  }
  EXPECT_EQ(files, 28);
  EXPECT_GT(total_vertices, 100000u);
}

TEST(MeshIoRealData, MotomanGp7MeshesLoad) {
  const auto data = test::data_dir();
  HAPSIM_SKIP_WITHOUT_DATA(data && fs::is_directory(*data / "motoman_gp7/meshes"),
                           "Motoman GP7 meshes not found");
  int files = 0;
  for (const char* kind : {"collision", "visual"}) {
    for (const auto& entry : fs::directory_iterator(*data / "motoman_gp7/meshes" / kind)) {
      if (entry.path().extension() != ".stl") {
        continue;
      }
      SCOPED_TRACE(entry.path().string());
      MeshReport r;
      const TriangleMesh m = load_mesh(entry.path(), {}, &r);  // metres already
      ++files;
      EXPECT_GT(m.triangle_count(), 10u);
      const Vec3 size = m.bounds().sizes();
      EXPECT_GT(size.maxCoeff(), 0.02);  // robot links are centimetres to a metre
      EXPECT_LT(size.maxCoeff(), 1.5);
      EXPECT_EQ(r.non_finite_vertices, 0u);
      EXPECT_EQ(r.out_of_range_triangles, 0u);
      std::cout << "  " << kind << "/" << entry.path().filename().string() << ": " << r.summary()
                << "\n";
    }
  }
  EXPECT_EQ(files, 14);
}

}  // namespace
}  // namespace hapsim
