#include "hapsim/scene/csg_reader.h"

#include "hapsim/core/error.h"
#include "hapsim/geometry/polygonizer.h"

#include <cmath>
#include <iomanip>
#include <span>
#include <sstream>
#include <vector>

namespace hapsim {
namespace {

using Json = JsonReader::Json;

constexpr const char* kKinds[] = {"box",   "sphere", "cylinder",     "cone",
                                  "torus", "union",  "intersection", "difference"};
constexpr const char* kKindList =
    "box, sphere, cylinder, cone, torus, union, intersection or difference";

// Folds a list as a balanced tree: a long union then costs log2(n) levels of recursion in
// every evaluation instead of n.
CsgSolid balanced(std::span<const CsgSolid> solids,
                  CsgSolid (*combine)(const CsgSolid&, const CsgSolid&)) {
  if (solids.size() == 1) {
    return solids[0];
  }
  const std::size_t half = solids.size() / 2;
  return combine(balanced(solids.first(half), combine), balanced(solids.subspan(half), combine));
}

class NodeReader {
 public:
  explicit NodeReader(const JsonReader& reader) : r_(reader) {}

  CsgSolid node(const Json& j, const std::string& ptr, int depth) {
    r_.object(j, ptr, std::string("a CSG solid (") + kKindList + ")");
    if (depth > kCsgMaxDepth) {
      r_.fail(ptr, "CSG solids nest at most " + std::to_string(kCsgMaxDepth) + " deep");
    }
    std::string kind;
    for (const char* k : kKinds) {
      if (j.contains(k)) {
        if (!kind.empty()) {
          r_.fail(ptr, "expected exactly one solid kind, got both '" + kind + "' and '" + k + "'");
        }
        kind = k;
      }
    }
    if (kind.empty()) {
      // An unknown key is the likelier mistake (a typo): name it.
      r_.allow_keys(j, ptr,
                    {"box", "sphere", "cylinder", "cone", "torus", "union", "intersection",
                     "difference", "pose"});
      r_.fail(ptr, std::string("expected one solid kind: ") + kKindList);
    }
    r_.allow_keys(j, ptr, {kind.c_str(), "pose"});
    const std::string kp = JsonReader::at(ptr, kind);
    CsgSolid solid;
    if (kind == "union" || kind == "intersection" || kind == "difference") {
      solid = boolean(kind, j[kind], kp, depth);
    } else {
      solid = primitive(kind, j[kind], kp);
    }
    if (j.contains("pose")) {
      solid = solid.transformed(r_.parse_pose(j["pose"], JsonReader::at(ptr, "pose")));
    }
    return solid;
  }

 private:
  // A required size > 0 (and <= 100 m, as the other geometry kinds).
  double size(const Json& obj, const std::string& ptr, const char* key) const {
    (void)r_.required(obj, ptr, key);
    return r_.number_in(obj, ptr, key, 0.0, 0.0, 100.0, "m", true);
  }

  CsgSolid primitive(const std::string& kind, const Json& j, const std::string& kp) {
    if (++primitives_ > kCsgMaxPrimitives) {
      r_.fail(kp, "a CSG solid has at most " + std::to_string(kCsgMaxPrimitives) +
                      " primitives (each is evaluated every haptic cycle)");
    }
    r_.object(j, kp, kind + " settings");
    if (kind == "box") {
      r_.allow_keys(j, kp, {"half_extents_m"});
      const std::string hp = JsonReader::at(kp, "half_extents_m");
      const Vec3 h = r_.vec3(r_.required(j, kp, "half_extents_m"), hp, "m");
      for (std::size_t i = 0; i < 3; ++i) {
        const double v = h[static_cast<Eigen::Index>(i)];
        if (!(v > 0.0) || v > 100.0) {
          std::ostringstream what;
          what << "expected a half extent > 0 and <= 100 m, got " << v;
          r_.fail(JsonReader::at(hp, i), what.str());
        }
      }
      return CsgSolid::block(h);
    }
    if (kind == "sphere") {
      r_.allow_keys(j, kp, {"radius_m"});
      return CsgSolid::sphere(size(j, kp, "radius_m"));
    }
    if (kind == "cylinder") {
      r_.allow_keys(j, kp, {"radius_m", "half_height_m"});
      const double radius = size(j, kp, "radius_m");
      return CsgSolid::cylinder(radius, size(j, kp, "half_height_m"));
    }
    if (kind == "cone") {
      r_.allow_keys(j, kp, {"radius_m", "height_m"});
      const double radius = size(j, kp, "radius_m");
      return CsgSolid::cone(radius, size(j, kp, "height_m"));
    }
    // torus
    r_.allow_keys(j, kp, {"major_radius_m", "minor_radius_m"});
    const double major = size(j, kp, "major_radius_m");
    const double minor = size(j, kp, "minor_radius_m");
    if (minor > major) {
      // A spindle torus overlaps itself across the axis; its distance formula is then wrong.
      std::ostringstream what;
      what << "expected a minor radius <= the major radius (" << major << " m), got " << minor;
      r_.fail(JsonReader::at(kp, "minor_radius_m"), what.str());
    }
    return CsgSolid::torus(major, minor);
  }

  CsgSolid boolean(const std::string& kind, const Json& j, const std::string& kp, int depth) {
    r_.array(j, kp, "a list of CSG solids");
    if (j.size() < 2) {
      r_.fail(kp, "expected at least 2 solids, got " + std::to_string(j.size()));
    }
    std::vector<CsgSolid> children;
    children.reserve(j.size());
    for (std::size_t i = 0; i < j.size(); ++i) {
      children.push_back(node(j[i], JsonReader::at(kp, i), depth + 1));
    }
    if (kind == "union") {
      return balanced(children, csg_union);
    }
    if (kind == "intersection") {
      return balanced(children, csg_intersection);
    }
    // a − b − c = a − (b ∪ c): the same distance max(a, −b, −c), one level deep.
    return csg_difference(children[0], balanced(std::span(children).subspan(1), csg_union));
  }

  const JsonReader& r_;
  std::size_t primitives_ = 0;
};

}  // namespace

CsgSolid read_csg_node(const JsonReader& reader, const Json& node, const std::string& ptr) {
  return NodeReader(reader).node(node, ptr, 1);
}

CsgGeometry read_csg_geometry(const JsonReader& reader, const Json& geometry,
                              const std::string& ptr, const ProgressFn& progress,
                              std::size_t grid_node_budget) {
  reader.allow_keys(geometry, ptr, {"csg", "resolution_m"});
  CsgGeometry g;
  const std::string cp = JsonReader::at(ptr, "csg");
  g.solid = read_csg_node(reader, geometry.at("csg"), cp);
  g.resolution_m = reader.number_in(geometry, ptr, "resolution_m", kCsgDefaultResolutionM,
                                    kCsgMinResolutionM, 0.1, "m");
  g.requested_resolution_m = g.resolution_m;
  const std::string rp =
      geometry.contains("resolution_m") ? JsonReader::at(ptr, "resolution_m") : ptr;
  PolygonizeOptions o;
  o.max_grid_nodes = kCsgMaxGridNodes;
  // Counted as the polygoniser does, so the refusal names the scene's own values.
  const Box3 bounds = g.solid.bounds();
  const Vec3 extent = bounds.isEmpty() ? Vec3::Zero() : Vec3(bounds.sizes());
  auto grid_nodes = [&](double cell_m) {
    double nodes = 1.0;
    for (int a = 0; a < 3; ++a) {
      nodes *= std::ceil(extent[a] / cell_m) + 1.0 + 2.0 * o.padding_cells;
    }
    return nodes;
  };
  const double nodes = grid_nodes(g.resolution_m);
  if (!(nodes <= static_cast<double>(kCsgMaxGridNodes))) {
    std::ostringstream what;
    what << std::setprecision(3) << "the solid's bounds (" << extent.x() << " x " << extent.y()
         << " x " << extent.z() << " m) at a resolution of " << g.resolution_m << " m need "
         << nodes << " grid nodes for the display mesh; at most " << kCsgMaxGridNodes
         << " are allowed: give a coarser resolution_m";
    reader.fail(rp, what.str());
  }
  // Bounded: the grid never has fewer nodes than the padding alone gives, so a budget below that
  // stops at the coarsest cell tried.
  for (int i = 0; i < 64 && grid_node_budget > 0 &&
                  grid_nodes(g.resolution_m) > static_cast<double>(grid_node_budget);
       ++i) {
    g.resolution_m *= 1.25;
  }
  o.cell_size_m = g.resolution_m;
  o.progress = progress;
  try {
    g.mesh = polygonize(g.solid, o);
  } catch (const Error& e) {
    // E.g. an empty solid (a sphere minus a bigger one), or one thinner than a cell everywhere.
    reader.fail(cp, "cannot polygonise the solid at " + std::to_string(g.resolution_m) +
                        " m: " + e.detail());
  }
  return g;
}

}  // namespace hapsim
