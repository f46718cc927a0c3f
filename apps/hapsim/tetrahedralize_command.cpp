// `hapsim tetrahedralize --outer SKIN.stl [--points BONE.stl]... [--drop BONE.stl]...
// [--region ID=PATTERN]... --out PREFIX`: a FEM body's volume from closed surfaces, meshed by
// TetGen run as a separate program (GPL: its output is data, hapsim never links it). The outer
// surface bounds the volume (TetGen's piecewise linear complex); the vertices of the --points
// meshes become mesh nodes, so the tets follow those surfaces (bones) without their triangles
// having to be free of self-intersection as a PLC's must; tets whose centre is inside a --drop
// mesh are removed (the rigid parts: the nodes left on them are where a scene fixes the tissue);
// the others get the region of the first --region whose surfaces contain their centre, else
// --default-region. Regions follow the surfaces to within a tet (centroid labelling), not along
// conforming faces. Writes PREFIX.node / PREFIX.ele (TetGen format, read by scenes' tet_mesh).
// Deterministic: the same inputs and switches give the same bytes (scripts/derive-knee-fem.sh).
#include "commands.h"
#include "json_output.h"

#include "hapsim/collision/mesh_bvh.h"
#include "hapsim/core/disjoint_sets.h"
#include "hapsim/core/error.h"
#include "hapsim/geometry/mesh_argument.h"
#include "hapsim/geometry/mesh_validation.h"
#include "hapsim/geometry/tet_mesh.h"
#include "hapsim/geometry/tet_mesh_io.h"

#include <fcntl.h>
#include <glob.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>  // environ

#include <algorithm>
#include <array>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <map>
#include <memory>
#include <sstream>

namespace hapsim::app {
namespace {

struct TetrahedralizeOptions {
  std::string outer;
  std::vector<std::string> points;
  std::vector<std::string> drop;
  std::vector<std::string> regions;
  int default_region = 0;
  std::string switches = "pq2.0";
  std::string tetgen = "tetgen";
  double scale = 1.0;
  double min_spacing_fraction = 2e-3;
  std::string out_prefix;
  std::string json_path;
};

// A closed surface with its exact signed distance, for "is this point inside".
struct Solid {
  std::string file;
  TriangleMesh mesh;
  std::unique_ptr<MeshBvh> query;
  Box3 bounds;
  [[nodiscard]] bool contains(const Vec3& p) const {
    return bounds.contains(p) && query->closest_point(p).signed_distance < 0.0;
  }
};

TriangleMesh load_closed(const std::string& file, const char* option) {
  TriangleMesh mesh;
  try {
    mesh = load_mesh_argument(file, 1.0).mesh;  // file units throughout, as TetGen sees them
  } catch (const Error& e) {
    throw CommandError(std::string(option) + " " + file + ": " + e.what());
  }
  const MeshReport report = validate_mesh(mesh);
  if (!report.closed) {
    throw CommandError(std::string(option) + " " + file + ": not a closed surface (" +
                       report.summary() + "); it has no inside");
  }
  return mesh;
}

std::vector<std::string> expand(const std::string& pattern, const char* option) {
  glob_t g{};
  const int rc = ::glob(pattern.c_str(), 0, nullptr, &g);
  std::vector<std::string> files;
  if (rc == 0) {
    for (std::size_t i = 0; i < g.gl_pathc; ++i) {
      files.emplace_back(g.gl_pathv[i]);
    }
  }
  ::globfree(&g);
  if (files.empty()) {
    throw CommandError(std::string(option) + " " + pattern + ": no such file");
  }
  std::sort(files.begin(), files.end());
  return files;
}

std::unique_ptr<Solid> make_solid(const std::string& file, const char* option) {
  auto s = std::make_unique<Solid>();
  s->file = file;
  s->mesh = load_closed(file, option);
  s->bounds = s->mesh.bounds();
  s->query = std::make_unique<MeshBvh>(s->mesh);  // after the move: it keeps a reference
  return s;
}

// Runs the mesher as a program (no shell), its output to `log`; throws with the log's tail.
void run_tetgen(const std::string& program, const std::string& switches,
                const std::filesystem::path& poly, const std::filesystem::path& log) {
  const std::string sw = "-" + switches + "iQ";
  std::vector<std::string> args{program, sw, poly.string()};
  std::vector<char*> argv;
  argv.reserve(args.size() + 1);
  for (std::string& a : args) {
    argv.push_back(a.data());
  }
  argv.push_back(nullptr);
  posix_spawn_file_actions_t actions;
  if (posix_spawn_file_actions_init(&actions) != 0) {
    throw CommandError("cannot prepare to run " + program + " (out of memory)");
  }
  const int open_rc = posix_spawn_file_actions_addopen(&actions, 1, log.c_str(),
                                                       O_WRONLY | O_CREAT | O_TRUNC, 0644);
  const int dup_rc = posix_spawn_file_actions_adddup2(&actions, 1, 2);
  pid_t pid = 0;
  const int rc = open_rc != 0 || dup_rc != 0
                     ? (open_rc != 0 ? open_rc : dup_rc)
                     : posix_spawnp(&pid, program.c_str(), &actions, nullptr, argv.data(), environ);
  posix_spawn_file_actions_destroy(&actions);
  if (open_rc != 0 || dup_rc != 0) {
    throw CommandError("cannot send " + program + "'s output to " + log.string() + " (" +
                       std::strerror(rc) + ")");
  }
  if (rc != 0) {
    throw CommandError("--tetgen " + program + ": cannot run it (" + std::strerror(rc) +
                       (rc == ENOENT ? "); on Debian: apt-get install tetgen" : ")"));
  }
  int status = 0;
  pid_t waited = 0;
  while ((waited = ::waitpid(pid, &status, 0)) < 0 && errno == EINTR) {
  }
  if (waited < 0) {
    throw CommandError("lost track of " + program + " (waitpid: " + std::strerror(errno) +
                       "): its output cannot be trusted");
  }
  if (!WIFEXITED(status) || WEXITSTATUS(status) != 0) {
    std::ifstream in(log);
    std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    if (text.size() > 600) {
      text = "..." + text.substr(text.size() - 600);
    }
    throw CommandError(program + " " + sw + " failed (" +
                       (WIFEXITED(status)
                            ? "exit " + std::to_string(WEXITSTATUS(status))
                            : "killed by signal " + std::to_string(WTERMSIG(status))) +
                       "); a self-intersecting --outer is the usual cause (check it with "
                       "'tetgen -d'). Its output:\n" +
                       text);
  }
}

// The mesher's own output (TetGen .node/.ele, first index as the file says), oriented
// positively. Not read_tetgen: that refuses a degenerate tet, and a few flat ones between
// inserted points that lie on one plane (a bone's cut) are expected here and removed by the
// caller. Throws CommandError naming the file on anything unreadable.
TetMesh read_mesher_output(const std::filesystem::path& prefix) {
  TetMesh mesh;
  const auto open = [&](const char* ext) {
    std::filesystem::path p = prefix;
    p += ext;
    auto in = std::make_unique<std::ifstream>(p);
    if (!*in) {
      throw CommandError(p.string() + ": the mesher wrote no such file");
    }
    return std::make_pair(std::move(in), p.string());
  };
  auto [node_in, node_path] = open(".node");
  std::size_t n = 0;
  int dim = 0;
  int attributes = 0;
  int markers = 0;
  if (!(*node_in >> n >> dim >> attributes >> markers) || dim != 3) {
    throw CommandError(node_path + ": not a TetGen node file");
  }
  std::int64_t first = -1;
  std::string line;
  std::getline(*node_in, line);
  for (std::size_t i = 0; i < n; ++i) {
    std::int64_t index = 0;
    Vec3 p;
    if (!(*node_in >> index >> p.x() >> p.y() >> p.z()) || !p.allFinite()) {
      throw CommandError(node_path + ": node " + std::to_string(i) + " unreadable");
    }
    std::getline(*node_in, line);  // attributes and markers
    first = first < 0 ? index : first;
    mesh.nodes.push_back(p);
  }
  auto [ele_in, ele_path] = open(".ele");
  std::size_t t_count = 0;
  int per_tet = 0;
  if (!(*ele_in >> t_count >> per_tet >> attributes) || per_tet != 4) {
    throw CommandError(ele_path + ": not a TetGen file of 4-node tetrahedra");
  }
  std::getline(*ele_in, line);
  for (std::size_t t = 0; t < t_count; ++t) {
    std::int64_t index = 0;
    std::array<std::int64_t, 4> k{};
    if (!(*ele_in >> index >> k[0] >> k[1] >> k[2] >> k[3])) {
      throw CommandError(ele_path + ": tet " + std::to_string(t) + " unreadable");
    }
    std::getline(*ele_in, line);
    TetIndices tet{};
    for (int j = 0; j < 4; ++j) {
      const std::int64_t v = k[j] - first;
      if (v < 0 || v >= static_cast<std::int64_t>(n)) {
        throw CommandError(ele_path + ": tet " + std::to_string(t) + " names no node");
      }
      tet[j] = static_cast<std::uint32_t>(v);
    }
    mesh.tets.push_back(tet);
    if (mesh.signed_volume(t) < 0.0) {
      std::swap(mesh.tets.back()[2], mesh.tets.back()[3]);
    }
  }
  return mesh;
}

// Keeps the tets connected (through shared nodes) to the piece with the most tets; returns how
// many were dropped. Pockets between dropped parts can leave tiny islands nothing holds.
std::size_t keep_largest_piece(TetMesh& mesh) {
  DisjointSets pieces(mesh.node_count());
  const auto find = [&](std::uint32_t v) { return pieces.find(v); };
  for (const TetIndices& t : mesh.tets) {
    for (int k = 1; k < 4; ++k) {
      pieces.unite(t[0], t[k]);
    }
  }
  std::map<std::uint32_t, std::size_t> count;
  for (const TetIndices& t : mesh.tets) {
    ++count[find(t[0])];
  }
  if (count.size() <= 1) {
    return 0;
  }
  const std::uint32_t largest = std::max_element(count.begin(), count.end(), [](auto& a, auto& b) {
                                  return a.second < b.second;
                                })->first;
  std::vector<TetIndices> tets;
  std::vector<std::int32_t> regions;
  for (std::size_t t = 0; t < mesh.tet_count(); ++t) {
    if (find(mesh.tets[t][0]) == largest) {
      tets.push_back(mesh.tets[t]);
      regions.push_back(mesh.region(t));
    }
  }
  const std::size_t dropped = mesh.tet_count() - tets.size();
  mesh.tets = std::move(tets);
  mesh.regions = std::move(regions);
  return dropped;
}

// Removes nodes no tet uses, renumbering in order (deterministic).
void remove_unused_nodes(TetMesh& mesh) {
  std::vector<std::int64_t> new_index(mesh.node_count(), -1);
  for (const TetIndices& t : mesh.tets) {
    for (const std::uint32_t n : t) {
      new_index[n] = 0;
    }
  }
  std::vector<Vec3> nodes;
  for (std::size_t i = 0; i < mesh.node_count(); ++i) {
    if (new_index[i] == 0) {
      new_index[i] = static_cast<std::int64_t>(nodes.size());
      nodes.push_back(mesh.nodes[i]);
    }
  }
  for (TetIndices& t : mesh.tets) {
    for (std::uint32_t& n : t) {
      n = static_cast<std::uint32_t>(new_index[n]);
    }
  }
  mesh.nodes = std::move(nodes);
}

void write_text(const std::filesystem::path& path, const std::string& text) {
  std::ofstream out(path);
  out << text;
  out.flush();
  if (!out) {
    throw CommandError(path.string() + ": cannot write (" + std::strerror(errno) + ")");
  }
}

void run_tetrahedralize(const TetrahedralizeOptions& opt) {
  if (opt.switches.find_first_not_of("0123456789.pqaAYTVOSe/") != std::string::npos ||
      opt.switches.find('p') == std::string::npos) {
    throw CommandError("--switches " + opt.switches +
                       ": expected TetGen switches with p (a PLC) and only p q a A Y T V O S e / "
                       "and numbers; hapsim adds i (the points) and Q");
  }
  JsonOutput json(opt.json_path);
  const TriangleMesh outer = load_closed(opt.outer, "--outer");
  // The mesher's input, in a fresh folder that goes away.
  char tmpl[] = "/tmp/hapsim-tetrahedralize-XXXXXX";
  if (::mkdtemp(tmpl) == nullptr) {
    throw CommandError(std::string("cannot make a working folder in /tmp: ") +
                       std::strerror(errno));
  }
  const std::filesystem::path work(tmpl);
  struct Cleanup {
    std::filesystem::path dir;
    ~Cleanup() {
      std::error_code ec;
      std::filesystem::remove_all(dir, ec);
    }
  } cleanup{work};

  std::ostringstream poly;
  poly.precision(17);
  poly << outer.vertex_count() << " 3 0 0\n";
  for (std::size_t i = 0; i < outer.vertex_count(); ++i) {
    const Vec3& p = outer.vertices[i];
    poly << i << ' ' << p.x() << ' ' << p.y() << ' ' << p.z() << '\n';
  }
  poly << outer.triangle_count() << " 0\n";
  for (const TriangleIndices& t : outer.triangles) {
    poly << "1\n3 " << t[0] << ' ' << t[1] << ' ' << t[2] << '\n';
  }
  poly << "0\n0\n";
  write_text(work / "in.poly", poly.str());

  // The inserted nodes: every vertex of the --points meshes inside the outer surface, once.
  const MeshBvh outer_query(outer);
  // A point on (or outside) the outer surface would make slivers against it, or be refused.
  const double inside_by = 1e-3 * outer.bounds().diagonal().norm();
  // Points closer than this to one kept already are left out: two nodes that near make flat
  // tets between them.
  const double spacing = opt.min_spacing_fraction * outer.bounds().diagonal().norm();
  std::map<std::array<std::int64_t, 3>, std::vector<Vec3>> grid;
  const auto cell_of = [&](const Vec3& p) {
    return std::array<std::int64_t, 3>{static_cast<std::int64_t>(std::floor(p.x() / spacing)),
                                       static_cast<std::int64_t>(std::floor(p.y() / spacing)),
                                       static_cast<std::int64_t>(std::floor(p.z() / spacing))};
  };
  const auto near_kept = [&](const Vec3& p) {
    const auto c = cell_of(p);
    for (int dx = -1; dx <= 1; ++dx) {
      for (int dy = -1; dy <= 1; ++dy) {
        for (int dz = -1; dz <= 1; ++dz) {
          const auto it = grid.find({c[0] + dx, c[1] + dy, c[2] + dz});
          if (it != grid.end()) {
            for (const Vec3& q : it->second) {
              if ((q - p).norm() < spacing) {
                return true;
              }
            }
          }
        }
      }
    }
    return false;
  };
  std::vector<Vec3> inserted;
  std::size_t outside = 0;
  std::size_t crowded = 0;
  for (const std::string& pattern : opt.points) {
    for (const std::string& file : expand(pattern, "--points")) {
      const TriangleMesh m = load_closed(file, "--points");
      for (const Vec3& p : m.vertices) {
        if (outer_query.closest_point(p).signed_distance > -inside_by) {
          ++outside;
          continue;
        }
        if (near_kept(p)) {
          ++crowded;
          continue;
        }
        grid[cell_of(p)].push_back(p);
        inserted.push_back(p);
      }
    }
  }
  std::ostringstream pts;
  pts.precision(17);
  pts << inserted.size() << " 3 0 0\n";
  for (std::size_t i = 0; i < inserted.size(); ++i) {
    pts << i << ' ' << inserted[i].x() << ' ' << inserted[i].y() << ' ' << inserted[i].z() << '\n';
  }
  write_text(work / "in.a.node", pts.str());

  std::printf("tetgen       -%siQ: %zu outer triangles, %zu inserted points", opt.switches.c_str(),
              outer.triangle_count(), inserted.size());
  if (outside > 0) {
    std::printf(" (%zu on or outside the outer surface left out)", outside);
  }
  if (crowded > 0) {
    std::printf(" (%zu within %.3g of another left out)", crowded, spacing);
  }
  std::printf("\n");
  std::fflush(stdout);
  run_tetgen(opt.tetgen, opt.switches, work / "in.poly", work / "tetgen.log");
  TetMesh mesh = read_mesher_output(work / "in.1");
  const std::size_t meshed = mesh.tet_count();

  // Label by each tet's centre.
  std::vector<std::unique_ptr<Solid>> drops;
  for (const std::string& pattern : opt.drop) {
    for (const std::string& file : expand(pattern, "--drop")) {
      drops.push_back(make_solid(file, "--drop"));
    }
  }
  std::vector<std::pair<int, std::unique_ptr<Solid>>> regions;
  for (const std::string& spec : opt.regions) {
    const auto eq = spec.find('=');
    int id = 0;
    try {
      std::size_t used = 0;
      id = eq == std::string::npos ? 0 : std::stoi(spec.substr(0, eq), &used);
      if (eq == std::string::npos || used != eq || id < 0) {
        throw std::invalid_argument("");
      }
    } catch (const std::exception&) {
      throw CommandError("--region " + spec + ": expected ID=FILE (ID a whole number >= 0)");
    }
    for (const std::string& file : expand(spec.substr(eq + 1), "--region")) {
      regions.emplace_back(id, make_solid(file, "--region"));
    }
  }
  std::vector<TetIndices> kept;
  std::vector<std::int32_t> labels;
  std::map<int, std::size_t> per_region;
  std::size_t dropped_inside = 0;
  std::size_t dropped_flat = 0;
  const double flat_volume = 1e-12 * std::pow(mesh.bounds().diagonal().norm(), 3.0);
  for (std::size_t t = 0; t < mesh.tet_count(); ++t) {
    const TetIndices& k = mesh.tets[t];
    if (std::abs(mesh.signed_volume(t)) <= flat_volume) {
      ++dropped_flat;
      continue;
    }
    const Vec3 c =
        0.25 * (mesh.nodes[k[0]] + mesh.nodes[k[1]] + mesh.nodes[k[2]] + mesh.nodes[k[3]]);
    if (std::any_of(drops.begin(), drops.end(), [&](const auto& s) { return s->contains(c); })) {
      ++dropped_inside;
      continue;
    }
    int label = opt.default_region;
    for (const auto& [id, solid] : regions) {
      if (solid->contains(c)) {
        label = id;
        break;
      }
    }
    kept.push_back(k);
    labels.push_back(label);
  }
  mesh.tets = std::move(kept);
  mesh.regions = std::move(labels);
  const std::size_t islands = keep_largest_piece(mesh);
  remove_unused_nodes(mesh);
  for (std::size_t t = 0; t < mesh.tet_count(); ++t) {
    ++per_region[mesh.region(t)];
  }
  try {
    validate_tet_mesh(mesh, opt.out_prefix);
  } catch (const Error& e) {
    throw CommandError(std::string("the labelled mesh is not usable: ") + e.what());
  }
  try {
    write_tetgen(mesh, opt.out_prefix);
  } catch (const Error& e) {
    throw CommandError(std::string("--out: ") + e.what());
  }

  const TetMeshQuality q = tet_mesh_quality(mesh);
  const double unit3_to_ml = opt.scale * opt.scale * opt.scale * 1e6;
  std::printf(
      "meshed       %zu tets; removed %zu inside --drop surfaces, %zu flat, %zu in islands\n",
      meshed, dropped_inside, dropped_flat, islands);
  std::printf(
      "volume       %zu tets, %zu nodes, %.1f mL; dihedral %.1f..%.1f deg, worst aspect %.1f\n",
      q.tets, q.nodes, q.total_volume_m3 * unit3_to_ml, q.min_dihedral_deg, q.max_dihedral_deg,
      q.max_aspect_ratio);
  nlohmann::json region_json = nlohmann::json::object();
  for (const auto& [id, n] : per_region) {
    double volume = 0.0;
    for (std::size_t t = 0; t < mesh.tet_count(); ++t) {
      if (mesh.region(t) == id) {
        volume += mesh.signed_volume(t);
      }
    }
    std::printf("region %-5d %zu tets, %.1f mL\n", id, n, volume * unit3_to_ml);
    region_json[std::to_string(id)] = {{"tets", n}, {"volume_ml", volume * unit3_to_ml}};
  }
  std::printf("wrote        %s.node, %s.ele\n", opt.out_prefix.c_str(), opt.out_prefix.c_str());
  if (json) {
    json.write({{"out", opt.out_prefix},
                {"switches", opt.switches},
                {"inserted_points", inserted.size()},
                {"meshed_tets", meshed},
                {"dropped_inside", dropped_inside},
                {"dropped_flat", dropped_flat},
                {"dropped_islands", islands},
                {"tets", q.tets},
                {"nodes", q.nodes},
                {"volume_ml", q.total_volume_m3 * unit3_to_ml},
                {"min_dihedral_deg", q.min_dihedral_deg},
                {"max_dihedral_deg", q.max_dihedral_deg},
                {"max_aspect_ratio", q.max_aspect_ratio},
                {"regions", region_json}});
  }
}

}  // namespace

void add_tetrahedralize_command(CLI::App& app) {
  auto opt = std::make_shared<TetrahedralizeOptions>();
  CLI::App* cmd = app.add_subcommand(
      "tetrahedralize",
      "A FEM body's volume from closed surfaces: meshed by TetGen (run as a program), the "
      "--drop parts removed, each tet labelled by the --region surface around its centre");
  cmd->add_option("--outer", opt->outer, "The closed surface that bounds the volume")->required();
  cmd->add_option("--points", opt->points,
                  "A closed mesh whose vertices become nodes (repeatable; * patterns expand)");
  cmd->add_option("--drop", opt->drop,
                  "Remove the tets whose centre is inside this closed mesh (repeatable; * "
                  "patterns expand)");
  cmd->add_option("--region", opt->regions,
                  "ID=FILE: tets whose centre is inside FILE get region ID; the first match wins "
                  "(repeatable; * patterns expand)");
  cmd->add_option("--default-region", opt->default_region, "The region of every other tet")
      ->check(CLI::NonNegativeNumber);
  cmd->add_option("--switches", opt->switches,
                  "TetGen switches (p needed; q radius-edge bound, a max volume in file units^3)");
  cmd->add_option("--tetgen", opt->tetgen, "The TetGen program");
  cmd->add_option("--min-spacing", opt->min_spacing_fraction,
                  "Leave out a --points vertex this near one kept, as a fraction of the outer "
                  "surface's bounding diagonal")
      ->check(CLI::Range(1e-6, 0.1));
  cmd->add_option("--scale", opt->scale,
                  "File units to metres, for the volumes printed (0.001 for millimetres); the "
                  "output stays in file units")
      ->check(CLI::PositiveNumber);
  cmd->add_option("--out", opt->out_prefix, "Write PREFIX.node and PREFIX.ele")->required();
  cmd->add_option("--json", opt->json_path, "Also write a summary as JSON to this file");
  cmd->callback([opt] { run_tetrahedralize(*opt); });
}

}  // namespace hapsim::app
