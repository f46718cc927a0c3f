// FemBody's linear static solve against CalculiX (ccx, Debian calculix-ccx), an independent FE
// code run as a separate program (GPL: never linked, test-only like CGAL). The test writes the
// .inp itself from the same TetMesh (C3D4 elements: ccx's linear tetrahedron has hapsim's node
// order and orientation), the same materials, fixed nodes and nodal loads, runs `ccx -i job` in a
// temporary folder, reads the nodal displacements from the .dat (*NODE PRINT) and compares every
// node. Shared with hapsim: only the mesh's numbers written as text.
//
// Only the linear, quasi-static case: ccx's *STATIC without NLGEOM is small-strain linear, so a
// corotational body under a large load is not expected to agree (and is not tested here).
#include "hapsim/deform/fem_body.h"
#include "hapsim/geometry/tet_mesh.h"

#include <gtest/gtest.h>

#include <sys/wait.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <optional>
#include <sstream>
#include <string>
#include <vector>

namespace hapsim {
namespace {

namespace fs = std::filesystem;

// What both solvers get.
struct OracleCase {
  std::string name;
  TetMesh mesh;
  std::vector<FemRegionMaterial> materials;
  std::vector<std::uint32_t> fixed_nodes;
  std::vector<FemNodeForce> loads;
};

// A real for the deck: ccx reads a number from at most 20 characters (a longer one is refused or,
// in a node's coordinates, cut), so 14 significant digits: "-1.2345678901234e-03".
std::string ccx_real(double x) {
  char text[32];
  std::snprintf(text, sizeof text, "%.13e", x);
  return text;
}

// The CalculiX input deck (SI units throughout: m, N, Pa). ccx numbers nodes and elements from 1:
// node i is i + 1 here. One element set and one material per region.
std::string ccx_deck(const OracleCase& c) {
  std::ostringstream out;
  out << "*HEADING\nhapsim FEM oracle: " << c.name << "\n";
  out << "*NODE, NSET=NALL\n";
  for (std::size_t i = 0; i < c.mesh.nodes.size(); ++i) {
    const Vec3& p = c.mesh.nodes[i];
    out << i + 1 << ", " << ccx_real(p.x()) << ", " << ccx_real(p.y()) << ", " << ccx_real(p.z())
        << "\n";
  }
  for (std::size_t m = 0; m < c.materials.size(); ++m) {
    out << "*ELEMENT, TYPE=C3D4, ELSET=R" << m << "\n";
    for (std::size_t t = 0; t < c.mesh.tets.size(); ++t) {
      if (c.mesh.region(t) != c.materials[m].region) {
        continue;
      }
      const TetIndices& tet = c.mesh.tets[t];
      out << t + 1 << ", " << tet[0] + 1 << ", " << tet[1] + 1 << ", " << tet[2] + 1 << ", "
          << tet[3] + 1 << "\n";
    }
  }
  // ccx reads at most 16 entries on a set's data line: 8 here.
  out << "*NSET, NSET=FIXED\n";
  for (std::size_t i = 0; i < c.fixed_nodes.size(); ++i) {
    out << c.fixed_nodes[i] + 1 << ((i % 8 == 7 || i + 1 == c.fixed_nodes.size()) ? "\n" : ", ");
  }
  for (std::size_t m = 0; m < c.materials.size(); ++m) {
    const FemMaterial& mat = c.materials[m].material;
    out << "*MATERIAL, NAME=M" << m << "\n*ELASTIC\n"
        << ccx_real(mat.youngs_modulus_pa) << ", " << ccx_real(mat.poisson_ratio) << "\n";
    out << "*SOLID SECTION, ELSET=R" << m << ", MATERIAL=M" << m << "\n";
  }
  out << "*BOUNDARY\nFIXED, 1, 3, 0.0\n";
  // SPOOLES: a direct sparse solve, so the oracle carries no iterative tolerance of its own.
  out << "*STEP\n*STATIC, SOLVER=SPOOLES\n*CLOAD\n";
  for (const FemNodeForce& load : c.loads) {
    for (int axis = 0; axis < 3; ++axis) {
      if (load.force_n[axis] != 0.0) {
        out << load.node + 1 << ", " << axis + 1 << ", " << ccx_real(load.force_n[axis]) << "\n";
      }
    }
  }
  out << "*NODE PRINT, NSET=NALL\nU\n*END STEP\n";
  return out.str();
}

// A Fortran E-format number; with a three-digit exponent Fortran drops the 'E' ("0.1-104").
std::optional<double> parse_fortran_double(std::string token) {
  if (token.find_first_of("eEdD") == std::string::npos) {
    const std::size_t sign = token.find_first_of("+-", 1);
    if (sign != std::string::npos) {
      token.insert(sign, "E");
    }
  }
  std::replace(token.begin(), token.end(), 'D', 'E');
  std::replace(token.begin(), token.end(), 'd', 'E');
  char* end = nullptr;
  const double value = std::strtod(token.c_str(), &end);
  if (end != token.c_str() + token.size() || !std::isfinite(value)) {
    return std::nullopt;
  }
  return value;
}

// The displacement block of ccx's .dat:
//  displacements (vx,vy,vz) for set NALL and time  0.1000000E+01
//  (blank line)
//          1  0.000000E+00  0.000000E+00  0.000000E+00
// Returns the displacement of every node (0-based), or an error message.
struct CcxResult {
  std::vector<Vec3> displacement_m;
  std::string error;
  fs::path folder;  ///< where ccx ran (deck, log, .dat)
};
CcxResult parse_ccx_dat(const fs::path& dat, std::size_t node_count) {
  CcxResult result;
  std::ifstream in(dat);
  if (!in) {
    result.error = "no " + dat.string();
    return result;
  }
  std::string line;
  bool found = false;
  while (std::getline(in, line)) {
    if (line.find("displacements (vx,vy,vz) for set NALL") != std::string::npos) {
      found = true;
      break;
    }
  }
  if (!found) {
    result.error = dat.string() + " has no displacement block for NALL";
    return result;
  }
  result.displacement_m.assign(node_count, Vec3::Zero());
  std::vector<bool> seen(node_count, false);
  std::size_t rows = 0;
  while (std::getline(in, line)) {
    std::istringstream fields(line);
    long long id = 0;
    std::string a, b, c;
    if (!(fields >> id)) {
      if (rows == 0 && line.find_first_not_of(" \t\r") == std::string::npos) {
        continue;  // the blank line after the heading
      }
      break;  // the block's end
    }
    if (!(fields >> a >> b >> c)) {
      result.error = dat.string() + ": short row: " + line;
      return result;
    }
    const auto ux = parse_fortran_double(a);
    const auto uy = parse_fortran_double(b);
    const auto uz = parse_fortran_double(c);
    if (!ux || !uy || !uz || id < 1 || static_cast<std::size_t>(id) > node_count) {
      result.error = dat.string() + ": unreadable row: " + line;
      return result;
    }
    const auto node = static_cast<std::size_t>(id - 1);
    result.displacement_m[node] = Vec3(*ux, *uy, *uz);
    seen[node] = true;
    ++rows;
  }
  const auto missing = std::find(seen.begin(), seen.end(), false);
  if (missing != seen.end()) {
    result.error = dat.string() + ": no displacement for node " +
                   std::to_string(missing - seen.begin() + 1) + " (ccx numbering)";
  }
  return result;
}

std::string read_text(const fs::path& path) {
  std::ifstream in(path);
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

// The last `lines` lines of a log, for a failure message.
std::string tail(const std::string& text, int lines) {
  std::size_t pos = text.size();
  for (int i = 0; i <= lines && pos != std::string::npos && pos > 0; ++i) {
    pos = text.rfind('\n', pos - 1);
  }
  return pos == std::string::npos ? text : text.substr(pos + 1);
}

// Runs ccx on the case in a fresh temporary folder (the caller removes it unless the test failed,
// so the deck, the log and the .dat can be inspected).
CcxResult run_ccx(const std::string& ccx, const OracleCase& c) {
  CcxResult result;
  std::string pattern = (fs::temp_directory_path() / "hapsim-ccx-XXXXXX").string();
  if (mkdtemp(pattern.data()) == nullptr) {
    result.error = "cannot make a temporary folder from " + pattern;
    return result;
  }
  const fs::path dir = pattern;
  {
    std::ofstream deck(dir / "job.inp");
    deck << ccx_deck(c);
    if (!deck) {
      result.error = "cannot write " + (dir / "job.inp").string();
      return result;
    }
  }
  // One thread (the machine is shared with the build), and a time limit: a case takes well under
  // a second.
  const std::string command = "cd '" + dir.string() + "' && OMP_NUM_THREADS=1 timeout 120 '" + ccx +
                              "' -i job > job.log 2>&1";
  const int status = std::system(command.c_str());
  const std::string log = read_text(dir / "job.log");
  if (status == -1 || !WIFEXITED(status) || WEXITSTATUS(status) != 0) {
    const int code = (status != -1 && WIFEXITED(status)) ? WEXITSTATUS(status) : -1;
    result.error = "ccx failed (exit " + std::to_string(code) +
                   (code == 124 ? ", killed after 120 s" : "") + ") in " + dir.string() + ":\n" +
                   tail(log, 15);
    return result;
  }
  // ccx exits 0 after an *ERROR in the deck: the log says.
  if (log.find("*ERROR") != std::string::npos) {
    result.error = "ccx reported an error in " + dir.string() + ":\n" + tail(log, 15);
    return result;
  }
  result = parse_ccx_dat(dir / "job.dat", c.mesh.node_count());
  result.folder = dir;
  if (!result.error.empty()) {
    result.error += " (ccx log in " + dir.string() + ")";
  }
  return result;
}

std::optional<std::string> ccx_path() {
#ifdef HAPSIM_CCX_PATH
  return std::string(HAPSIM_CCX_PATH);
#else
  return std::nullopt;
#endif
}

// The issue asks 1 %. Both codes assemble the same constant-strain tetrahedron and solve directly,
// so they agree far better, to the .dat's 7 printed digits: measured 1.5e-7 (cantilever) and
// 2.0e-7 (two-region block) of the largest displacement. The control case below is 2.9e-2.
constexpr double kTolerance = 0.01;

struct Comparison {
  /// max over nodes |u_hapsim − u_ccx| / max over nodes |u_ccx|
  double relative = INFINITY;
  fs::path ccx_folder;
};

// Leaves ccx's folder (deck, log, .dat) for inspection when the test failed.
void finish(const Comparison& r) {
  if (r.ccx_folder.empty()) {
    return;
  }
  if (::testing::Test::HasFailure()) {
    std::printf("ccx's deck, log and results kept in %s\n", r.ccx_folder.string().c_str());
  } else {
    std::error_code ignored;
    fs::remove_all(r.ccx_folder, ignored);
  }
}

// Solves the case with both codes (hapsim with `hapsim_materials` when given: the control case).
Comparison compare_with_ccx(const OracleCase& c,
                            const std::vector<FemRegionMaterial>* hapsim_materials = nullptr) {
  Comparison r;
  const auto ccx = ccx_path();
  if (!ccx) {
    ADD_FAILURE() << "internal: compare_with_ccx without HAPSIM_CCX_PATH";
    return r;
  }
  if (!fs::exists(*ccx)) {
    ADD_FAILURE() << "ccx not found at " << *ccx
                  << " (found at configure time): install calculix-ccx (scripts/setup.sh does)";
    return r;
  }
  validate_tet_mesh(c.mesh, c.name);
  const CcxResult oracle = run_ccx(*ccx, c);
  r.ccx_folder = oracle.folder;
  if (!oracle.error.empty()) {
    ADD_FAILURE() << oracle.error;
    return r;
  }

  FemOptions options;
  options.elasticity = FemElasticity::kLinear;
  options.integration = FemIntegration::kQuasiStatic;
  FemBody body(c.mesh, hapsim_materials ? *hapsim_materials : c.materials, c.fixed_nodes, options,
               c.name);
  body.set_loads(c.loads);
  const FemStepStats stats = body.solve_static();
  EXPECT_TRUE(stats.converged);
  EXPECT_EQ(body.rejected_loads(), 0U);

  double largest_m = 0.0;
  for (const Vec3& u : oracle.displacement_m) {
    largest_m = std::max(largest_m, u.norm());
  }
  EXPECT_GT(largest_m, 0.0) << "ccx: no displacement at all";
  double worst_m = 0.0;
  std::size_t worst_node = 0;
  for (std::size_t i = 0; i < c.mesh.node_count(); ++i) {
    const auto node = static_cast<std::uint32_t>(i);
    const double difference_m = (body.displacement(node) - oracle.displacement_m[i]).norm();
    if (!(difference_m <= worst_m)) {  // also catches NaN
      worst_m = difference_m;
      worst_node = i;
    }
  }
  r.relative = worst_m / largest_m;
  std::printf(
      "%s: %zu nodes, %zu tets, max |u| %.4g mm (ccx); worst node %zu differs by %.3g mm "
      "= %.3g of max |u|\n",
      c.name.c_str(), c.mesh.node_count(), c.mesh.tet_count(), largest_m * 1e3, worst_node,
      worst_m * 1e3, r.relative);
  ::testing::Test::RecordProperty("max_relative_difference", std::to_string(r.relative));
  return r;
}

std::vector<std::uint32_t> nodes_where(const TetMesh& mesh, int axis, double value_m) {
  std::vector<std::uint32_t> out;
  for (std::size_t i = 0; i < mesh.nodes.size(); ++i) {
    if (std::abs(mesh.nodes[i][axis] - value_m) < 1e-9) {
      out.push_back(static_cast<std::uint32_t>(i));
    }
  }
  return out;
}

// A deterministic value in [−1, 1] per (node, axis): portable, unlike <random>'s distributions.
double hash_unit(std::size_t node, int axis) {
  std::uint64_t h = (static_cast<std::uint64_t>(node) << 2U) ^ static_cast<std::uint64_t>(axis);
  h = (h ^ (h >> 33U)) * 0xff51afd7ed558ccdULL;
  h = (h ^ (h >> 33U)) * 0xc4ceb9fe1a85ec53ULL;
  h ^= h >> 33U;
  return static_cast<double>(h >> 11U) / static_cast<double>(1ULL << 52U) * 2.0 - 1.0;
}

#define HAPSIM_SKIP_WITHOUT_CCX()                                             \
  if (!ccx_path()) {                                                          \
    GTEST_SKIP() << "ccx (calculix-ccx) not found at configure time; "        \
                    "HAPSIM_REQUIRE_ORACLES=ON makes that a configure error"; \
  }

// A 40 × 10 × 10 mm bar clamped at x = 0, a tip load (mostly down, some sideways and axial)
// shared by the end face's nodes: bending in two planes plus stretching.
OracleCase cantilever_case() {
  OracleCase c;
  c.name = "cantilever";
  c.mesh = make_tet_block(Vec3(0.040, 0.010, 0.010), {16, 4, 4});
  FemMaterial material;
  material.youngs_modulus_pa = 1e6;
  material.poisson_ratio = 0.3;
  c.materials = {{0, material}};
  c.fixed_nodes = nodes_where(c.mesh, 0, 0.0);
  const std::vector<std::uint32_t> tip = nodes_where(c.mesh, 0, 0.040);
  const Vec3 tip_force_n(0.02, 0.05, -0.2);
  for (const std::uint32_t node : tip) {
    c.loads.push_back({node, tip_force_n / static_cast<double>(tip.size())});
  }
  return c;
}

TEST(FemCalculixOracle, CantileverTipLoadMatchesCcx) {
  HAPSIM_SKIP_WITHOUT_CCX();
  const OracleCase c = cantilever_case();
  ASSERT_EQ(c.fixed_nodes.size(), 25U);
  ASSERT_EQ(c.loads.size(), 25U);
  const Comparison r = compare_with_ccx(c);
  EXPECT_LT(r.relative, kTolerance);
  finish(r);
}

// The comparison can fail: hapsim given a modulus 3 % too high is caught (bending deflection goes
// as 1/E, so about 3 % of the tip's displacement).
TEST(FemCalculixOracle, ComparisonCatchesAModulusThreePercentOff) {
  HAPSIM_SKIP_WITHOUT_CCX();
  OracleCase c = cantilever_case();
  c.name = "cantilever, hapsim's E 3 % high";
  std::vector<FemRegionMaterial> off = c.materials;
  off[0].material.youngs_modulus_pa *= 1.03;
  const Comparison r = compare_with_ccx(c, &off);
  EXPECT_GT(r.relative, 0.02);
  EXPECT_LT(r.relative, 0.04);
  finish(r);
}

// A 32 × 32 × 16 mm block on a table (bottom face fixed): a stiff lower layer (E 200 kPa, ν 0.3)
// under a soft, nearly incompressible upper one (20 kPa, 0.45), interior nodes jittered so the
// mesh is irregular, and a Gaussian patch of pressure on the top pushing down and a little
// sideways.
TEST(FemCalculixOracle, TwoRegionBlockUnderTopPressureMatchesCcx) {
  HAPSIM_SKIP_WITHOUT_CCX();
  OracleCase c;
  c.name = "two-region block";
  const double cell_m = 0.004;
  c.mesh = make_tet_block(Vec3(0.032, 0.032, 0.016), {8, 8, 4});
  // Regions by the rest centroid: the layers meet at z = 8 mm, a plane of cell faces.
  c.mesh.regions.assign(c.mesh.tet_count(), 0);
  for (std::size_t t = 0; t < c.mesh.tet_count(); ++t) {
    double z_m = 0.0;
    for (const std::uint32_t n : c.mesh.tets[t]) {
      z_m += 0.25 * c.mesh.nodes[n].z();
    }
    c.mesh.regions[t] = z_m < 0.008 ? 1 : 0;
  }
  const Box3 box = c.mesh.bounds();
  for (std::size_t i = 0; i < c.mesh.node_count(); ++i) {
    Vec3& p = c.mesh.nodes[i];
    const bool inside = (p.array() > box.min().array() + 1e-9).all() &&
                        (p.array() < box.max().array() - 1e-9).all();
    if (inside) {
      // ±10 % of a cell per axis keeps every tet well clear of inversion.
      p += 0.1 * cell_m * Vec3(hash_unit(i, 0), hash_unit(i, 1), hash_unit(i, 2));
    }
  }
  FemMaterial soft;
  soft.youngs_modulus_pa = 20e3;
  soft.poisson_ratio = 0.45;
  FemMaterial stiff;
  stiff.youngs_modulus_pa = 200e3;
  stiff.poisson_ratio = 0.3;
  c.materials = {{0, soft}, {1, stiff}};
  c.fixed_nodes = nodes_where(c.mesh, 2, 0.0);
  ASSERT_EQ(c.fixed_nodes.size(), 81U);

  const std::vector<std::uint32_t> top = nodes_where(c.mesh, 2, 0.016);
  const Vec3 centre_m(0.016, 0.016, 0.016);
  const double sigma_m = 0.006;
  std::vector<double> weights;
  double weight_sum = 0.0;
  for (const std::uint32_t node : top) {
    const double r2 = (c.mesh.nodes[node] - centre_m).squaredNorm();
    weights.push_back(std::exp(-r2 / (2.0 * sigma_m * sigma_m)));
    weight_sum += weights.back();
  }
  const Vec3 total_force_n(0.03, 0.01, -0.3);
  for (std::size_t k = 0; k < top.size(); ++k) {
    c.loads.push_back({top[k], total_force_n * (weights[k] / weight_sum)});
  }
  const Comparison r = compare_with_ccx(c);
  EXPECT_LT(r.relative, kTolerance);
  finish(r);
}

}  // namespace
}  // namespace hapsim
