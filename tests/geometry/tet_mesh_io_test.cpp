// The three tet mesh readers against small files written here by hand (so each reader is checked
// against content known independently: node positions, tets, regions), a block written by the
// test in each format and read back identical, and bad files: each refused with one error naming
// the file and the line or element.
#include "hapsim/geometry/tet_mesh_io.h"

#include "hapsim/core/error.h"

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <limits>
#include <sstream>
#include <string>

namespace hapsim {
namespace {

namespace fs = std::filesystem;

class TetMeshIo : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ =
        fs::temp_directory_path() /
        ("hapsim_tet_mesh_io_" + std::to_string(::testing::UnitTest::GetInstance()->random_seed()) +
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
  // The error reading `path` gives (what()), or "" when it reads.
  static std::string error_reading(const fs::path& path) {
    try {
      (void)read_tet_mesh(path);
    } catch (const Error& e) {
      return e.what();
    }
    return "";
  }
  fs::path dir_;
};

// Two tets sharing the face (1,2,3): the corner tet (volume 1/6) and one reaching (1,1,1)
// (volume 1/3). Nodes in the order below; both tets positively oriented as listed.
const std::vector<Vec3> kTwoTetNodes = {Vec3(0, 0, 0), Vec3(1, 0, 0), Vec3(0, 1, 0), Vec3(0, 0, 1),
                                        Vec3(1, 1, 1)};
const std::vector<TetIndices> kTwoTets = {{0, 1, 2, 3}, {1, 2, 3, 4}};

// Gmsh 4.1: two volumes (entity tags 1 and 2) in physical groups 11 and 22; node tags sparse
// (10..50) in two blocks; a surface block (triangles) to be skipped.
constexpr const char* kTwoTetMsh = R"($MeshFormat
4.1 0 8
$EndMeshFormat
$PhysicalNames
2
3 11 "soft"
3 22 "hard"
$EndPhysicalNames
$Entities
0 0 1 2
5 0 0 0 1 1 0 0 0
1 0 0 0 1 1 1 1 11 0
2 0 0 0 1 1 1 1 22 0
$EndEntities
$Nodes
2 5 10 50
3 1 0 3
10
20
30
1 0 0
0 0 0
0 1 0
3 2 0 2
40
50
0 0 1
1 1 1
$EndNodes
$Elements
3 4 1 4
2 5 2 2
1 20 30 40
2 30 50 40
3 1 4 1
3 20 10 30 40
3 2 4 1
4 10 30 40 50
$EndElements
)";

TEST_F(TetMeshIo, GmshTwoRegionsWithPhysicalTagsAndSparseNodeTags) {
  const TetMesh m = read_gmsh_msh4(write("two.msh", kTwoTetMsh));
  // Node tags 10,20,30,40,50 hold (1,0,0),(0,0,0),(0,1,0),(0,0,1),(1,1,1), in file order.
  ASSERT_EQ(m.node_count(), 5u);
  EXPECT_EQ(m.nodes[0], Vec3(1, 0, 0));
  EXPECT_EQ(m.nodes[1], Vec3(0, 0, 0));
  EXPECT_EQ(m.nodes[4], Vec3(1, 1, 1));
  ASSERT_EQ(m.tet_count(), 2u);  // the two triangles were skipped
  EXPECT_EQ(m.tets[0], (TetIndices{1, 0, 2, 3}));
  EXPECT_EQ(m.tets[1], (TetIndices{0, 2, 3, 4}));
  EXPECT_EQ(m.regions, (std::vector<std::int32_t>{11, 22}));
  EXPECT_NEAR(m.volume(), 0.5, 1e-15);
}

TEST_F(TetMeshIo, GmshWithoutEntitiesUsesTheEntityTagAndFlipsAConsistentlyReversedFile) {
  std::string text = kTwoTetMsh;
  text.erase(text.find("$Entities"), text.find("$Nodes") - text.find("$Entities"));
  // Every tet the other way round: a file's convention, flipped silently.
  text.replace(text.find("3 20 10 30 40"), 13, "3 10 20 30 40");
  text.replace(text.find("4 10 30 40 50"), 13, "4 30 10 40 50");
  const TetMesh m = read_gmsh_msh4(write("reversed.msh", text));
  EXPECT_EQ(m.regions, (std::vector<std::int32_t>{1, 2}));
  EXPECT_NEAR(m.volume(), 0.5, 1e-15);
  for (std::size_t t = 0; t < m.tet_count(); ++t) {
    EXPECT_GT(m.signed_volume(t), 0.0);
  }
}

TEST_F(TetMeshIo, TetgenOneBasedWithRegionAttributesAndComments) {
  const std::string node = R"(# five nodes, 1-based, one attribute, boundary markers
5 3 1 1
1  0 0 0  7.5  1
2  1 0 0  7.5  1
3  0 1 0  7.5  1   # a comment after a node
4  0 0 1  7.5  0
5  1 1 1  7.5  1
)";
  const std::string ele = R"(2 4 1
# tetgen -A writes the region as the attribute
1  1 2 3 4  3
2  2 3 4 5  -4
)";
  write("two.node", node);
  const fs::path ele_path = write("two.ele", ele);
  for (const fs::path& p : {dir_ / "two.node", ele_path}) {
    const TetMesh m = read_tetgen(p);
    ASSERT_EQ(m.nodes, kTwoTetNodes);
    EXPECT_EQ(m.tets, kTwoTets);
    EXPECT_EQ(m.regions, (std::vector<std::int32_t>{3, -4}));
  }
  // 0-based numbering, no attributes: every tet region 0.
  const TetMesh zero = parse_tetgen("5 3 0 0\n0 0 0 0\n1 1 0 0\n2 0 1 0\n3 0 0 1\n4 1 1 1\n",
                                    "2 4 0\n0 0 1 2 3\n1 1 2 3 4\n", "zero");
  EXPECT_EQ(zero.tets, kTwoTets);
  EXPECT_TRUE(zero.regions.empty());
  EXPECT_EQ(zero.region(1), 0);
}

constexpr const char* kTwoTetVtk = R"(# vtk DataFile Version 2.0
two tets and a triangle # not a comment: the title
ASCII
DATASET UNSTRUCTURED_GRID
POINTS 5 double
0 0 0 1 0 0 0 1 0
0 0 1 1 1 1
CELLS 3 14
3 1 2 3
4 0 1 2 3
4 1 2 3 4
CELL_TYPES 3
5
10
10
CELL_DATA 3
SCALARS other float 1
LOOKUP_TABLE default
0.5 0.5 0.5
SCALARS region int 1
LOOKUP_TABLE default
9
5
6
POINT_DATA 5
VECTORS displacement double
0 0 0 0 0 0 0 0 0 0 0 0 0 0 0
)";

TEST_F(TetMeshIo, VtkLegacyWithCellDataRegionSkippingSurfaceCells) {
  const TetMesh m = read_vtk_unstructured(write("two.vtk", kTwoTetVtk));
  EXPECT_EQ(m.nodes, kTwoTetNodes);
  EXPECT_EQ(m.tets, kTwoTets);
  EXPECT_EQ(m.regions, (std::vector<std::int32_t>{5, 6}));
}

TEST_F(TetMeshIo, VtkFiveOneOffsetsAndAFieldArrayAsMeshioWritesThem) {
  const std::string text = R"(# vtk DataFile Version 5.1
written by meshio
ASCII
DATASET UNSTRUCTURED_GRID
POINTS 5 double
0 0 0
1 0 0
0 1 0
0 0 1
1 1 1
CELLS 3 8
OFFSETS vtktypeint64
0 4 8
CONNECTIVITY vtktypeint64
0 1 2 3
1 2 3 4
CELL_TYPES 2
10
10
CELL_DATA 2
FIELD FieldData 2
gmsh:geometrical 1 2 int
1 2
gmsh:physical 1 2 int
31 32
)";
  const TetMesh m = parse_vtk_unstructured(text, "meshio.vtk");
  EXPECT_EQ(m.nodes, kTwoTetNodes);
  EXPECT_EQ(m.tets, kTwoTets);
  EXPECT_EQ(m.regions, (std::vector<std::int32_t>{31, 32}));
}

// ---- writers for the round trip ---------------------------------------------------------------

std::string number(double v) {
  std::ostringstream s;
  s.precision(std::numeric_limits<double>::max_digits10);
  s << v;
  return s.str();
}

std::string write_msh(const TetMesh& m) {
  // One volume entity per region, physical tag = region; node tags 1-based.
  std::vector<std::int32_t> regions(m.regions);
  std::sort(regions.begin(), regions.end());
  regions.erase(std::unique(regions.begin(), regions.end()), regions.end());
  std::ostringstream s;
  s << "$MeshFormat\n4.1 0 8\n$EndMeshFormat\n$Entities\n0 0 0 " << regions.size() << "\n";
  for (std::size_t e = 0; e < regions.size(); ++e) {
    s << e + 1 << " 0 0 0 1 1 1 1 " << regions[e] << " 0\n";
  }
  s << "$EndEntities\n$Nodes\n1 " << m.node_count() << " 1 " << m.node_count() << "\n3 1 0 "
    << m.node_count() << "\n";
  for (std::size_t i = 0; i < m.node_count(); ++i) {
    s << i + 1 << "\n";
  }
  for (const Vec3& p : m.nodes) {
    s << number(p.x()) << " " << number(p.y()) << " " << number(p.z()) << "\n";
  }
  s << "$EndNodes\n$Elements\n"
    << regions.size() << " " << m.tet_count() << " 1 " << m.tet_count() << "\n";
  std::size_t tag = 1;
  for (std::size_t e = 0; e < regions.size(); ++e) {
    const auto n = std::count(m.regions.begin(), m.regions.end(), regions[e]);
    s << "3 " << e + 1 << " 4 " << n << "\n";
    for (std::size_t t = 0; t < m.tet_count(); ++t) {
      if (m.regions[t] == regions[e]) {
        const TetIndices& k = m.tets[t];
        s << tag++ << " " << k[0] + 1 << " " << k[1] + 1 << " " << k[2] + 1 << " " << k[3] + 1
          << "\n";
      }
    }
  }
  s << "$EndElements\n";
  return s.str();
}

// TetGen's files as TetGen numbers them (from 1), written here apart from the library's own
// writer (from 0), so the reader is checked against both numberings.
void write_tetgen_one_based(const TetMesh& m, const fs::path& stem) {
  std::ofstream node(fs::path(stem).concat(".node"));
  node << m.node_count() << " 3 0 0\n";
  for (std::size_t i = 0; i < m.node_count(); ++i) {
    node << i + 1 << " " << number(m.nodes[i].x()) << " " << number(m.nodes[i].y()) << " "
         << number(m.nodes[i].z()) << "\n";
  }
  std::ofstream ele(fs::path(stem).concat(".ele"));
  ele << m.tet_count() << " 4 1\n";
  for (std::size_t t = 0; t < m.tet_count(); ++t) {
    const TetIndices& k = m.tets[t];
    ele << t + 1 << " " << k[0] + 1 << " " << k[1] + 1 << " " << k[2] + 1 << " " << k[3] + 1 << " "
        << m.regions[t] << "\n";
  }
}

std::string write_vtk(const TetMesh& m) {
  std::ostringstream s;
  s << "# vtk DataFile Version 3.0\nblock\nASCII\nDATASET UNSTRUCTURED_GRID\nPOINTS "
    << m.node_count() << " double\n";
  for (const Vec3& p : m.nodes) {
    s << number(p.x()) << " " << number(p.y()) << " " << number(p.z()) << "\n";
  }
  s << "CELLS " << m.tet_count() << " " << 5 * m.tet_count() << "\n";
  for (const TetIndices& k : m.tets) {
    s << "4 " << k[0] << " " << k[1] << " " << k[2] << " " << k[3] << "\n";
  }
  s << "CELL_TYPES " << m.tet_count() << "\n";
  for (std::size_t t = 0; t < m.tet_count(); ++t) {
    s << "10\n";
  }
  s << "CELL_DATA " << m.tet_count() << "\nSCALARS CellEntityIds int 1\nLOOKUP_TABLE default\n";
  for (const std::int32_t r : m.regions) {
    s << r << "\n";
  }
  return s.str();
}

TEST_F(TetMeshIo, ABlockWrittenInEachFormatReadsBackIdentical) {
  TetMesh block = make_tet_block(Vec3(0.1, 0.07, 0.03), {4, 3, 2});
  for (std::size_t t = 0; t < block.tet_count(); ++t) {
    block.regions.push_back(block.nodes[block.tets[t][0]].x() < 0.05 ? 1 : 2);
  }
  // The Gmsh writer groups tets by region: compare per region, in order.
  const auto by_region = [](const TetMesh& m, std::int32_t r) {
    std::vector<TetIndices> out;
    for (std::size_t t = 0; t < m.tet_count(); ++t) {
      if (m.regions[t] == r) {
        out.push_back(m.tets[t]);
      }
    }
    return out;
  };
  const TetMesh msh = read_tet_mesh(write("block.msh", write_msh(block)));
  EXPECT_EQ(msh.nodes, block.nodes);
  ASSERT_EQ(msh.tet_count(), block.tet_count());
  EXPECT_EQ(by_region(msh, 1), by_region(block, 1));
  EXPECT_EQ(by_region(msh, 2), by_region(block, 2));

  write_tetgen_one_based(block, dir_ / "block");
  const TetMesh tetgen = read_tet_mesh(dir_ / "block.ele");
  EXPECT_EQ(tetgen.nodes, block.nodes);
  EXPECT_EQ(tetgen.tets, block.tets);
  EXPECT_EQ(tetgen.regions, block.regions);

  // The library's writer (hapsim tetrahedralize's output): bit for bit back, the same bytes twice.
  TetMesh odd = block;
  for (Vec3& p : odd.nodes) {
    p += Vec3(1.0 / 3.0, -2.0 / 7.0, 1e-17);  // digits a short format would round away
  }
  hapsim::write_tetgen(odd, dir_ / "ours");
  const TetMesh ours = read_tet_mesh(dir_ / "ours.node");
  EXPECT_EQ(ours.nodes, odd.nodes);
  EXPECT_EQ(ours.tets, odd.tets);
  EXPECT_EQ(ours.regions, odd.regions);
  hapsim::write_tetgen(ours, dir_ / "again");
  const auto bytes = [](const fs::path& p) {
    std::ifstream in(p, std::ios::binary);
    return std::string(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
  };
  EXPECT_EQ(bytes(dir_ / "again.node"), bytes(dir_ / "ours.node"));
  EXPECT_EQ(bytes(dir_ / "again.ele"), bytes(dir_ / "ours.ele"));
  EXPECT_THROW(hapsim::write_tetgen(odd, dir_ / "no_such_folder" / "x"), Error);

  const TetMesh vtk = read_tet_mesh(write("block.vtk", write_vtk(block)));
  EXPECT_EQ(vtk.nodes, block.nodes);
  EXPECT_EQ(vtk.tets, block.tets);
  EXPECT_EQ(vtk.regions, block.regions);
}

TEST_F(TetMeshIo, ChoosesTheReaderByExtension) {
  EXPECT_TRUE(is_tet_mesh_path("a/b.msh"));
  EXPECT_TRUE(is_tet_mesh_path("b.NODE"));
  EXPECT_TRUE(is_tet_mesh_path("b.ele"));
  EXPECT_TRUE(is_tet_mesh_path("b.vtk"));
  EXPECT_FALSE(is_tet_mesh_path("b.stl"));
  EXPECT_FALSE(is_tet_mesh_path("b.vtu"));
  const std::string e = error_reading(write("b.stl", "solid x\nendsolid x\n"));
  EXPECT_NE(e.find("b.stl"), std::string::npos) << e;
  EXPECT_NE(e.find("not a tet mesh file"), std::string::npos) << e;
}

// ---- bad files: one error each, naming the file and the line or element ----------------------

// Expects reading `name` with `text` to fail with a message holding the file and each of `parts`.
#define EXPECT_REFUSED(name, text, ...)                                               \
  do {                                                                                \
    const fs::path path_ = write(name, text);                                         \
    const std::string e_ = error_reading(path_);                                      \
    EXPECT_NE(e_.find(path_.string()), std::string::npos) << e_;                      \
    for (const std::string part_ : {__VA_ARGS__}) {                                   \
      EXPECT_NE(e_.find(part_), std::string::npos) << "'" << part_ << "' in: " << e_; \
    }                                                                                 \
  } while (false)

std::string replace(std::string text, const std::string& from, const std::string& to) {
  const auto at = text.find(from);
  EXPECT_NE(at, std::string::npos) << from;
  return at == std::string::npos ? text : text.replace(at, from.size(), to);
}

TEST_F(TetMeshIo, GmshBadFilesAreRefusedWithFileAndLineOrElement) {
  // Mixed orientation: the second tet inverted, at line 38 of the file.
  EXPECT_REFUSED("inverted.msh", replace(kTwoTetMsh, "4 10 30 40 50", "4 30 10 40 50"),
                 "inverted.msh:38: element 1: inverted (signed volume -0.333 file units^3)");
  // Degenerate: a repeated node.
  EXPECT_REFUSED("degenerate.msh", replace(kTwoTetMsh, "4 10 30 40 50", "4 10 30 40 40"),
                 "degenerate.msh:38: element 1: degenerate (volume 0 file units^3)");
  // Two pieces: the second tet moved away from the first.
  {
    std::string apart = replace(kTwoTetMsh, "$Nodes\n2 5 10 50", "$Nodes\n2 9 10 90");
    apart = replace(apart, "3 2 0 2\n40\n50\n", "3 2 0 6\n40\n50\n60\n70\n80\n90\n");
    apart = replace(apart, "0 0 1\n1 1 1\n", "0 0 1\n1 1 1\n5 5 5\n6 5 5\n5 6 5\n5 5 6\n");
    apart = replace(apart, "4 10 30 40 50", "4 60 70 80 90");
    EXPECT_REFUSED("apart.msh", apart,
                   "2 disconnected pieces (element 0 and element 1 are not connected); one "
                   "body is one piece");
  }
  EXPECT_REFUSED("nan.msh", replace(kTwoTetMsh, "1 1 1\n$EndNodes", "1 nan 1\n$EndNodes"),
                 "nan.msh:28:", "not a finite number");
  EXPECT_REFUSED("range.msh", replace(kTwoTetMsh, "4 10 30 40 50", "4 10 30 40 99"),
                 "range.msh:38:", "element 1 (tag 4): node tag 99 is not in $Nodes");
  EXPECT_REFUSED("truncated.msh", std::string(kTwoTetMsh).substr(0, 300), "truncated");
  EXPECT_REFUSED("v2.msh", "$MeshFormat\n2.2 0 8\n$EndMeshFormat\n$Nodes\n0\n$EndNodes\n",
                 "v2.msh:2:", "MSH version 2.2 is not supported");
  EXPECT_REFUSED(
      "hex.msh",
      "$MeshFormat\n4.1 0 8\n$EndMeshFormat\n$Nodes\n1 1 1 1\n3 1 0 1\n1\n0 0 0\n"
      "$EndNodes\n$Elements\n1 1 1 1\n3 1 5 1\n1 1 1 1 1 1 1 1 1\n$EndElements\n",
      "hex.msh:12:", "element type 5 (8-node hexahedron) is not supported: linear tetrahedra only");
  EXPECT_REFUSED("huge.msh",
                 "$MeshFormat\n4.1 0 8\n$EndMeshFormat\n$Nodes\n1 4000000000 1 "
                 "4000000000\n$EndNodes\n",
                 "huge.msh:5:", "more than the rest of the file can hold");
  EXPECT_REFUSED("negative.msh",
                 "$MeshFormat\n4.1 0 8\n$EndMeshFormat\n$Nodes\n-1 5 1 5\n$EndNodes\n",
                 "negative.msh:5:", "out of range");
  EXPECT_REFUSED("surface.msh",
                 "$MeshFormat\n4.1 0 8\n$EndMeshFormat\n$Nodes\n1 3 1 3\n2 1 0 3\n1\n2\n3\n"
                 "0 0 0\n1 0 0\n0 1 0\n$EndNodes\n$Elements\n1 1 1 1\n2 1 2 1\n1 1 2 3\n"
                 "$EndElements\n",
                 "no tetrahedra");
}

TEST_F(TetMeshIo, BinaryMshIsRefusedByName) {
  // What gmsh -bin writes: the file type 1, then the integer 1 in binary (NUL bytes).
  std::string binary = "$MeshFormat\n4.1 1 8\n";
  binary += std::string("\x01\x00\x00\x00", 4);
  binary += "\n$EndMeshFormat\n";
  EXPECT_REFUSED("binary.msh", binary, "binary MSH is not supported; save as ASCII 4.1");
  try {
    (void)parse_gmsh_msh4("$MeshFormat\n4.1 1 8\n$EndMeshFormat\n", "text.msh");
    FAIL();
  } catch (const Error& e) {
    EXPECT_STREQ(e.what(), "text.msh:2: binary MSH is not supported; save as ASCII 4.1");
  }
}

TEST_F(TetMeshIo, TetgenBadFilesAreRefusedWithFileAndLine) {
  const std::string node = "5 3 0 0\n1 0 0 0\n2 1 0 0\n3 0 1 0\n4 0 0 1\n5 1 1 1\n";
  const auto refuse = [&](const std::string& name, const std::string& node_text,
                          const std::string& ele_text, const std::string& part) {
    write(name + ".node", node_text);
    const fs::path ele = write(name + ".ele", ele_text);
    const std::string e = error_reading(ele);
    EXPECT_NE(e.find(part), std::string::npos) << "'" << part << "' in: " << e;
  };
  refuse("inverted", node, "2 4 0\n1 1 2 3 4\n2 3 2 4 5\n",
         (dir_ / "inverted.ele").string() +
             ":3: element 1: inverted (signed volume -0.333 file units^3)");
  refuse("range", node, "2 4 0\n1 1 2 3 4\n2 2 3 4 9\n",
         (dir_ / "range.ele").string() +
             ":3: element 1: node 9 out of range (the .node file has 5 nodes numbered from 1)");
  refuse("nan", replace(node, "5 1 1 1", "5 1 NaN 1"), "2 4 0\n1 1 2 3 4\n2 2 3 4 5\n",
         (dir_ / "nan.node").string() + ":6:");
  refuse("truncated", node, "2 4 0\n1 1 2 3 4\n2 2 3\n",
         (dir_ / "truncated.ele").string() + ":3: unexpected end of file");
  refuse("quadratic", node, "1 10 0\n1 1 2 3 4 5 5 5 5 5 5\n", "10-node elements are not");
  refuse("degenerate", node, "2 4 0\n1 1 2 3 4\n2 2 3 4 4\n",
         (dir_ / "degenerate.ele").string() + ":3: element 1: degenerate");
  // The .ele alone.
  const fs::path lonely = write("lonely.ele", "1 4 0\n1 1 2 3 4\n");
  const std::string e = error_reading(lonely);
  EXPECT_NE(e.find("lonely.node"), std::string::npos) << e;
}

TEST_F(TetMeshIo, VtkBadFilesAreRefusedWithFileAndLineOrElement) {
  EXPECT_REFUSED("inverted.vtk", replace(kTwoTetVtk, "4 1 2 3 4", "4 2 1 3 4"),
                 "inverted.vtk:11: element 1: inverted (signed volume -0.333 file units^3)");
  EXPECT_REFUSED("range.vtk", replace(kTwoTetVtk, "4 1 2 3 4", "4 1 2 3 9"),
                 "range.vtk:11: element 1 (cell 2): node 9 out of range (the mesh has 5 nodes)");
  EXPECT_REFUSED("nan.vtk", replace(kTwoTetVtk, "0 0 1 1 1 1", "0 0 1 1 inf 1"),
                 "nan.vtk:7:", "not a finite number");
  EXPECT_REFUSED("hex.vtk",
                 replace(kTwoTetVtk, "CELL_TYPES 3\n5\n10\n10", "CELL_TYPES 3\n5\n10\n12"),
                 "cell type 12 (hexahedron) is not supported: linear tetrahedra only");
  EXPECT_REFUSED("truncated.vtk", std::string(kTwoTetVtk).substr(0, 120), "truncated");
  EXPECT_REFUSED("binary.vtk", replace(kTwoTetVtk, "ASCII", "BINARY"), "binary VTK");
  EXPECT_REFUSED("polydata.vtk", replace(kTwoTetVtk, "UNSTRUCTURED_GRID", "POLYDATA"),
                 "DATASET POLYDATA");
  EXPECT_REFUSED("huge.vtk",
                 "# vtk DataFile Version 3.0\nx\nASCII\nDATASET UNSTRUCTURED_GRID\n"
                 "POINTS 999999999999 double\n0 0 0\n",
                 "huge.vtk:5:", "out of range");
  EXPECT_REFUSED("types.vtk",
                 replace(kTwoTetVtk, "CELL_TYPES 3\n5\n10\n10", "CELL_TYPES 2\n10\n10"),
                 "CELL_TYPES lists 2 types for 3 cells");
}

}  // namespace
}  // namespace hapsim
