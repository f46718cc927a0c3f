#include "hapsim/scene/scene_file.h"

#include "hapsim/core/data_dir.h"
#include "hapsim/core/error.h"
#include "hapsim/core/device_profile.h"
#include "hapsim/geometry/mesh_io.h"
#include "hapsim/geometry/procedural.h"
#include "hapsim/geometry/procedural_knee.h"
#include "hapsim/core/device_io.h"
#include "hapsim/scene/csg_reader.h"
#include "hapsim/scene/json_reader.h"

#include <nlohmann/json.hpp>

#include <algorithm>
#include <cctype>
#include <cmath>
#include <fstream>
#include <map>
#include <optional>
#include <set>
#include <sstream>

namespace hapsim {
namespace {

using Json = nlohmann::json;

std::string lower(std::string s) {
  std::transform(s.begin(), s.end(), s.begin(),
                 [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  return s;
}

// The parser: carries the file name for messages, the folders paths resolve against, and the
// materials and bodies read so far for cross-references.
class Parser : public JsonReader {
 public:
  Parser(std::filesystem::path file, const SceneLoadOptions& options)
      : JsonReader(std::move(file)), options_(options) {}

  SceneDescription parse(const Json& root);

 private:
  std::filesystem::path path(const Json& j, const std::string& ptr, const std::string& what) {
    const std::string s = nonempty_string(j, ptr, what);
    if (s.rfind("data:", 0) == 0) {
      return data_dir(ptr) / s.substr(5);
    }
    const std::filesystem::path p(s);
    return p.is_absolute() ? p : file_.parent_path() / p;
  }

  std::filesystem::path data_dir(const std::string& ptr) {
    if (!options_.data_dir.empty()) {
      if (!std::filesystem::is_directory(options_.data_dir)) {
        fail(ptr, "the data folder " + options_.data_dir.string() + " does not exist");
      }
      return options_.data_dir;
    }
    // ../shared/data beside the checkout holding scenes/: <checkout>/scenes/x.json.
    const std::filesystem::path beside =
        std::filesystem::absolute(file_).parent_path().parent_path().parent_path() / "shared" /
        "data";
    const std::optional<std::filesystem::path> root = find_data_dir(beside);
    if (!root) {
      fail(ptr, "needs the real-data folder: set HAPSIM_DATA or give --data DIR (looked in " +
                    beside.lexically_normal().string() + ")");
    }
    std::filesystem::path dir = *root / data_default_;
    if (!std::filesystem::is_directory(dir)) {
      fail(ptr,
           "needs the data folder " + dir.string() + ", which does not exist; give --data DIR");
    }
    return dir;
  }

  void parse_materials(const Json& j, const std::string& ptr, WorldDescription& world);
  void parse_body(const Json& j, const std::string& ptr, WorldDescription& world);
  void parse_geometry(const Json& j, const std::string& ptr, BodyDescription& body,
                      std::vector<std::optional<TissueKind>>& tissues);
  void parse_body_materials(const Json& j, const std::string& ptr, BodyDescription& body,
                            const std::vector<std::optional<TissueKind>>& tissues);
  ToolDescription parse_tool(const Json& j, const std::string& ptr) const;
  void parse_device(const Json& j, const std::string& ptr, SceneDescription& scene);
  void parse_teleop(const Json& j, const std::string& ptr, TeleopSceneDescription& t);
  void parse_teleop_device(const Json& j, const std::string& ptr, SceneDescription& scene);
  void parse_run(const Json& root, SceneDescription& scene) const;
  void parse_glove_palpation(const Json& j, const std::string& ptr, SceneDescription& scene) const;
  std::uint32_t material_ref(const Json& j, const std::string& ptr) const;

  SceneLoadOptions options_;
  std::string data_default_;
  std::map<std::string, std::uint32_t> material_index_;
};

SceneDescription Parser::parse(const Json& root) {
  object(root, "", "a scene");
  const bool teleop = root.is_object() && root.contains("teleop");
  if (teleop) {
    allow_keys(root, "", {"$schema", "format", "description", "data", "teleop", "device", "run"});
  } else {
    allow_keys(root, "",
               {"$schema", "format", "description", "data", "world", "materials", "bodies", "tools",
                "device", "run"});
  }
  const Json& format = required(root, "", "format");
  if (!format.is_string() || format.get<std::string>() != "hapsim-scene/1") {
    fail("/format", "expected \"hapsim-scene/1\", got " + shown(format));
  }
  SceneDescription scene;
  scene.file = file_;
  if (root.contains("description")) {
    scene.description = string(root["description"], "/description", "a description");
  }
  if (root.contains("data")) {
    const Json& data = object(root["data"], "/data", "the data folder settings");
    allow_keys(data, "/data", {"default"});
    data_default_ = nonempty_string(required(data, "/data", "default"), "/data/default",
                                    "a folder under the data root");
  }
  scene.world.name = file_.stem().string();
  if (teleop) {
    scene.is_teleop = true;
    parse_teleop(root["teleop"], "/teleop", scene.teleop);
    parse_teleop_device(required(root, "", "device"), "/device", scene);
    parse_run(root, scene);
    report_progress(options_.progress, "scene: loaded", 1.0);
    return scene;
  }
  if (root.contains("world")) {
    const Json& w = object(root["world"], "/world", "world settings");
    allow_keys(w, "/world", {"name", "passivity_damping_factor"});
    if (w.contains("name")) {
      scene.world.name = nonempty_string(w["name"], "/world/name", "a world name");
    }
    scene.world.passivity_damping_factor =
        number_in(w, "/world", "passivity_damping_factor", 1.0, 0.0, 100.0, "");
  }
  parse_materials(required(root, "", "materials"), "/materials", scene.world);

  const Json& bodies = array(required(root, "", "bodies"), "/bodies", "a list of bodies");
  if (bodies.empty()) {
    fail("/bodies", "expected at least one body");
  }
  std::set<std::string> body_names;
  for (std::size_t i = 0; i < bodies.size(); ++i) {
    report_progress(options_.progress, "scene: bodies",
                    static_cast<double>(i) / static_cast<double>(bodies.size()));
    parse_body(bodies[i], at("/bodies", i), scene.world);
    if (!body_names.insert(scene.world.bodies.back().name).second) {
      fail(at(at("/bodies", i), "name"),
           "expected a unique body name; '" + scene.world.bodies.back().name + "' is used twice");
    }
  }

  const Json& tools = array(required(root, "", "tools"), "/tools", "a list of tools");
  if (tools.empty()) {
    fail("/tools", "expected at least one tool (the device drives its tools)");
  }
  std::set<std::string> tool_names;
  std::set<int> fingers;
  for (std::size_t i = 0; i < tools.size(); ++i) {
    scene.world.tools.push_back(parse_tool(tools[i], at("/tools", i)));
    const ToolDescription& t = scene.world.tools.back();
    if (!tool_names.insert(t.name).second) {
      fail(at(at("/tools", i), "name"),
           "expected a unique tool name; '" + t.name + "' is used twice");
    }
    if (t.finger >= 0 && !fingers.insert(t.finger).second) {
      fail(at(at("/tools", i), "finger"),
           "expected each finger actuator to drive one tool; finger " + std::to_string(t.finger) +
               " is used twice");
    }
  }

  parse_device(required(root, "", "device"), "/device", scene);

  parse_run(root, scene);
  // Palpation targets must name what exists.
  if (scene.device.has_palpation) {
    for (std::size_t i = 0; i < scene.device.palpation.targets.size(); ++i) {
      const PalpationTargetDescription& t = scene.device.palpation.targets[i];
      const std::string p = at("/device/palpation/targets", i);
      const auto body = std::find_if(scene.world.bodies.begin(), scene.world.bodies.end(),
                                     [&](const BodyDescription& b) { return b.name == t.body; });
      if (body == scene.world.bodies.end()) {
        fail(at(p, "body"), "expected the name of a body in /bodies, got '" + t.body + "'");
      }
      if (std::none_of(body->segments.begin(), body->segments.end(),
                       [&](const SegmentDescription& s) { return s.name == t.segment; })) {
        std::string names;
        for (std::size_t s = 0; s < body->segments.size() && s < 40; ++s) {
          names += (names.empty() ? "" : ", ") + body->segments[s].name;
        }
        fail(at(p, "segment"), "expected a segment of body '" + t.body + "' (" + names +
                                   "), got '" + t.segment + "'");
      }
    }
  }
  report_progress(options_.progress, "scene: loaded", 1.0);
  return scene;
}

void Parser::parse_materials(const Json& j, const std::string& ptr, WorldDescription& world) {
  object(j, ptr, "materials by name");
  if (j.empty()) {
    fail(ptr, "expected at least one material");
  }
  for (const auto& [name, m] : j.items()) {
    const std::string p = at(ptr, name);
    object(m, p, "a material");
    allow_keys(m, p,
               {"description", "response", "stiffness_n_per_m", "max_penetration_m", "max_force_n",
                "damping_n_s_per_m", "static_friction", "dynamic_friction", "deformation"});
    MaterialDescription md;
    md.name = name;
    if (m.contains("response")) {
      md.response = one_of(m["response"], at(p, "response"), {"proxy", "penalty"}) == "proxy"
                        ? ContactResponse::kProxy
                        : ContactResponse::kPenalty;
    }
    ContactMaterial& c = md.contact;
    c.stiffness_n_per_m =
        number_in(m, p, "stiffness_n_per_m", c.stiffness_n_per_m, 0.0, 1e7, "N/m", true);
    c.max_penetration_m =
        number_in(m, p, "max_penetration_m", c.max_penetration_m, 0.0, 1.0, "m", true);
    c.max_force_n = number_in(m, p, "max_force_n", c.max_force_n, 0.0, 1e4, "N", true);
    c.damping_n_s_per_m =
        number_in(m, p, "damping_n_s_per_m", c.damping_n_s_per_m, 0.0, 1e5, "N*s/m");
    c.static_friction = number_in(m, p, "static_friction", c.static_friction, 0.0, 10.0, "");
    c.dynamic_friction = number_in(m, p, "dynamic_friction", c.dynamic_friction, 0.0, 10.0, "");
    if (c.dynamic_friction > c.static_friction) {
      fail(at(p, "dynamic_friction"), "expected dynamic friction <= static friction (" +
                                          std::to_string(c.static_friction) + ")");
    }
    if (m.contains("deformation")) {
      const std::string dp = at(p, "deformation");
      const Json& d = object(m["deformation"], dp, "deformation parameters");
      allow_keys(d, dp,
                 {"elasticity_factor", "recovery_time_constant_s", "max_recovery_speed_m_per_s",
                  "max_deflection_m"});
      DeflectionParams& f = md.deflection;
      f.elasticity_factor =
          number_in(d, dp, "elasticity_factor", f.elasticity_factor, 0.0, 100.0, "", true);
      f.recovery_time_constant_s = number_in(d, dp, "recovery_time_constant_s",
                                             f.recovery_time_constant_s, 0.0, 3600.0, "seconds");
      f.max_recovery_speed_m_per_s =
          number_in(d, dp, "max_recovery_speed_m_per_s", f.max_recovery_speed_m_per_s, 0.0, kInf,
                    "m/s", true, true);
      f.max_deflection_m =
          number_in(d, dp, "max_deflection_m", f.max_deflection_m, 0.0, kInf, "m", true, true);
    }
    material_index_[name] = static_cast<std::uint32_t>(world.materials.size());
    world.materials.push_back(std::move(md));
  }
}

std::uint32_t Parser::material_ref(const Json& j, const std::string& ptr) const {
  const std::string name = nonempty_string(j, ptr, "a material name");
  const auto it = material_index_.find(name);
  if (it == material_index_.end()) {
    std::string names;
    for (const auto& [n, i] : material_index_) {
      names += (names.empty() ? "" : ", ") + n;
    }
    fail(ptr, "expected the name of a material in /materials (" + names + "), got '" + name + "'");
  }
  return it->second;
}

void Parser::parse_body(const Json& j, const std::string& ptr, WorldDescription& world) {
  object(j, ptr, "a body");
  allow_keys(j, ptr, {"name", "type", "pose", "contact_method", "geometry", "materials"});
  BodyDescription body;
  body.name = nonempty_string(required(j, ptr, "name"), at(ptr, "name"), "a body name");
  if (j.contains("type")) {
    const std::string t = one_of(j["type"], at(ptr, "type"), {"static", "deformable", "dynamic"});
    body.kind = t == "static"       ? BodyKind::kStatic
                : t == "deformable" ? BodyKind::kDeformable
                                    : BodyKind::kDynamic;
  }
  if (j.contains("pose")) {
    body.X_world_body = parse_pose(j["pose"], at(ptr, "pose"));
  }
  if (j.contains("contact_method")) {
    const std::string m =
        one_of(j["contact_method"], at(ptr, "contact_method"), {"exact", "spheretree", "knee"});
    body.method = m == "exact"        ? ContactMethod::kExact
                  : m == "spheretree" ? ContactMethod::kSphereTree
                                      : ContactMethod::kKnee;
  }
  std::vector<std::optional<TissueKind>> tissues;
  parse_geometry(required(j, ptr, "geometry"), at(ptr, "geometry"), body, tissues);
  parse_body_materials(required(j, ptr, "materials"), at(ptr, "materials"), body, tissues);
  world.bodies.push_back(std::move(body));
}

void Parser::parse_geometry(const Json& j, const std::string& ptr, BodyDescription& body,
                            std::vector<std::optional<TissueKind>>& tissues) {
  object(j, ptr, "a geometry");
  const char* kinds[] = {"procedural", "box", "sphere", "sheet", "mesh", "mesh_folder", "csg"};
  std::string kind;
  for (const char* k : kinds) {
    if (j.contains(k)) {
      if (!kind.empty()) {
        fail(ptr, "expected exactly one geometry kind, got both '" + kind + "' and '" + k + "'");
      }
      kind = k;
    }
  }
  if (kind.empty()) {
    fail(ptr,
         "expected one geometry kind: procedural, box, sphere, sheet, mesh, mesh_folder or csg");
  }
  const std::string kp = at(ptr, kind);
  auto add = [&](std::string name, TriangleMesh mesh, std::optional<TissueKind> tissue,
                 bool two_sided = false) {
    SegmentDescription s;
    s.name = std::move(name);
    s.mesh = std::move(mesh);
    s.two_sided = two_sided;
    body.segments.push_back(std::move(s));
    tissues.push_back(tissue);
  };
  if (kind == "procedural") {
    allow_keys(j, ptr, {"procedural", "resolution_scale", "include_skin"});
    one_of(j["procedural"], kp, {"knee"});
    ProceduralKneeOptions o;
    o.resolution_scale = number_in(j, ptr, "resolution_scale", 1.0, 0.25, 4.0, "", true);
    if (j.contains("include_skin")) {
      if (!j["include_skin"].is_boolean()) {
        fail(at(ptr, "include_skin"), "expected true or false, got " + shown(j["include_skin"]));
      }
      o.include_skin = j["include_skin"].get<bool>();
    }
    report_progress(options_.progress, "scene: generating the procedural knee", 0.0);
    for (KneePart& part : make_procedural_knee(o)) {
      add(part.name, std::move(part.mesh), part.tissue);
    }
    return;
  }
  if (kind == "csg") {
    report_progress(options_.progress, "scene: polygonising the CSG solid of " + body.name, 0.0);
    CsgGeometry g = read_csg_geometry(*this, j, ptr, options_.progress);
    add(body.name, std::move(g.mesh), std::nullopt);
    body.segments.back().csg = std::move(g.solid);
    return;
  }
  allow_keys(j, ptr, {kind.c_str()});
  if (kind == "box") {
    const Json& b = object(j[kind], kp, "box settings");
    allow_keys(b, kp, {"half_extents_m"});
    const Vec3 h = vec3(required(b, kp, "half_extents_m"), at(kp, "half_extents_m"), "m");
    if (!(h.minCoeff() > 0.0)) {
      fail(at(kp, "half_extents_m"), "expected half extents > 0 m");
    }
    add(body.name, make_box(h), std::nullopt);
  } else if (kind == "sphere") {
    const Json& s = object(j[kind], kp, "sphere settings");
    allow_keys(s, kp, {"radius_m", "segments"});
    if (!s.contains("radius_m")) {
      fail(kp, "missing required key 'radius_m'");
    }
    const double r = number_in(s, kp, "radius_m", 0.0, 0.0, 100.0, "m", true);
    const auto n = static_cast<int>(number_in(s, kp, "segments", 64, 8, 1024, ""));
    add(body.name, make_uv_sphere(r, n, n / 2), std::nullopt);
  } else if (kind == "sheet") {
    const Json& s = object(j[kind], kp, "sheet settings");
    allow_keys(s, kp, {"size_m", "nodes_per_side"});
    if (!s.contains("size_m")) {
      fail(kp, "missing required key 'size_m'");
    }
    const double size = number_in(s, kp, "size_m", 0.0, 0.0, 100.0, "m", true);
    const auto n = static_cast<int>(number_in(s, kp, "nodes_per_side", 32, 2, 2048, ""));
    add(body.name, make_sheet(n, size), std::nullopt, true);
  } else if (kind == "mesh" || kind == "mesh_folder") {
    const Json& m = object(j[kind], kp, kind + " settings");
    if (kind == "mesh") {
      allow_keys(m, kp, {"file", "scale"});
    } else {
      allow_keys(m, kp, {"folder", "pattern", "scale", "strip_prefix", "strip_suffix"});
    }
    MeshLoadOptions lo;
    lo.scale = number_in(m, kp, "scale", 1.0, 0.0, 1e6, "metres per file unit", true);
    auto load = [&](const std::filesystem::path& file, const std::string& p) {
      try {
        return load_mesh(file, lo);
      } catch (const Error& e) {
        fail(p, "cannot load mesh " + e.where() + ": " + e.detail());
      }
    };
    if (kind == "mesh") {
      const std::string fp = at(kp, "file");
      const std::filesystem::path file = path(required(m, kp, "file"), fp, "a mesh file path");
      add(body.name, load(file, fp), std::nullopt);
    } else {
      const std::string fp = at(kp, "folder");
      const std::filesystem::path folder = path(required(m, kp, "folder"), fp, "a folder path");
      if (!std::filesystem::is_directory(folder)) {
        fail(fp, "expected a folder of mesh files; " + folder.string() + " is not a folder");
      }
      std::string pattern = "*.stl";
      if (m.contains("pattern")) {
        pattern = nonempty_string(m["pattern"], at(kp, "pattern"), "a file pattern like *.stl");
        if (pattern.rfind('*', 0) != 0 || pattern.find('*', 1) != std::string::npos) {
          fail(at(kp, "pattern"), "expected '*' followed by a file-name ending, e.g. '*.stl'");
        }
      }
      const std::string ending = lower(pattern.substr(1));
      const std::string prefix = m.contains("strip_prefix")
                                     ? string(m["strip_prefix"], at(kp, "strip_prefix"), "text")
                                     : "";
      const std::string suffix = m.contains("strip_suffix")
                                     ? string(m["strip_suffix"], at(kp, "strip_suffix"), "text")
                                     : "";
      std::vector<std::filesystem::path> files;
      for (const auto& entry : std::filesystem::directory_iterator(folder)) {
        const std::string name = lower(entry.path().filename().string());
        if (entry.is_regular_file() && name.size() >= ending.size() &&
            name.compare(name.size() - ending.size(), ending.size(), ending) == 0) {
          files.push_back(entry.path());
        }
      }
      std::sort(files.begin(), files.end());
      if (files.empty()) {
        fail(fp, "no file matching '" + pattern + "' in " + folder.string());
      }
      std::set<std::string> names;
      for (std::size_t i = 0; i < files.size(); ++i) {
        report_progress(options_.progress, "scene: loading " + files[i].filename().string(),
                        static_cast<double>(i) / static_cast<double>(files.size()));
        std::string name = files[i].stem().string();
        if (!prefix.empty() && name.rfind(prefix, 0) == 0) {
          name = name.substr(prefix.size());
        }
        if (!suffix.empty() && name.size() > suffix.size() &&
            name.compare(name.size() - suffix.size(), suffix.size(), suffix) == 0) {
          name = name.substr(0, name.size() - suffix.size());
        }
        if (!names.insert(name).second) {
          fail(fp, "two files give the segment name '" + name + "'");
        }
        add(name, load(files[i], fp), std::nullopt);
      }
    }
  }
}

void Parser::parse_body_materials(const Json& j, const std::string& ptr, BodyDescription& body,
                                  const std::vector<std::optional<TissueKind>>& tissues) {
  // A plain string: one material for every segment.
  if (j.is_string()) {
    const std::uint32_t m = material_ref(j, ptr);
    for (SegmentDescription& s : body.segments) {
      s.material = m;
    }
    return;
  }
  object(j, ptr, "a material name or material rules");
  allow_keys(j, ptr, {"default", "by_tissue", "by_name", "segments"});
  std::optional<std::uint32_t> fallback;
  if (j.contains("default")) {
    fallback = material_ref(j["default"], at(ptr, "default"));
  }
  std::map<std::string, std::uint32_t> by_tissue;
  if (j.contains("by_tissue")) {
    const std::string tp = at(ptr, "by_tissue");
    for (const auto& item : object(j["by_tissue"], tp, "materials by tissue").items()) {
      const std::string& tissue = item.key();
      const Json& name = item.value();
      const char* known[] = {"bone", "cartilage", "muscle", "tendon", "ligament", "skin"};
      if (std::none_of(std::begin(known), std::end(known),
                       [&](const char* k) { return tissue == k; })) {
        fail(at(tp, tissue), "unknown tissue '" + tissue +
                                 "'; expected bone, cartilage, muscle, tendon, ligament or skin");
      }
      by_tissue[tissue] = material_ref(name, at(tp, tissue));
    }
  }
  std::vector<std::pair<std::string, std::uint32_t>> by_name;
  if (j.contains("by_name")) {
    const std::string np = at(ptr, "by_name");
    const Json& rules = array(j["by_name"], np, "name rules");
    for (std::size_t i = 0; i < rules.size(); ++i) {
      const std::string rp = at(np, i);
      object(rules[i], rp, "a name rule {contains, material}");
      allow_keys(rules[i], rp, {"contains", "material"});
      const std::string text =
          nonempty_string(required(rules[i], rp, "contains"), at(rp, "contains"), "text");
      by_name.emplace_back(lower(text),
                           material_ref(required(rules[i], rp, "material"), at(rp, "material")));
    }
  }
  std::map<std::string, std::uint32_t> by_segment;
  if (j.contains("segments")) {
    const std::string sp = at(ptr, "segments");
    for (const auto& item : object(j["segments"], sp, "materials by segment").items()) {
      const std::string& name = item.key();
      const Json& m = item.value();
      if (std::none_of(body.segments.begin(), body.segments.end(),
                       [&](const SegmentDescription& s) { return s.name == name; })) {
        fail(at(sp, name),
             "expected the name of a segment of body '" + body.name + "', got '" + name + "'");
      }
      by_segment[name] = material_ref(m, at(sp, name));
    }
  }
  // Most specific first: the segment's own entry, a name rule, its tissue, the default.
  for (std::size_t i = 0; i < body.segments.size(); ++i) {
    SegmentDescription& s = body.segments[i];
    if (const auto it = by_segment.find(s.name); it != by_segment.end()) {
      s.material = it->second;
      continue;
    }
    const std::string name = lower(s.name);
    const auto rule = std::find_if(by_name.begin(), by_name.end(), [&](const auto& r) {
      return name.find(r.first) != std::string::npos;
    });
    if (rule != by_name.end()) {
      s.material = rule->second;
      continue;
    }
    if (tissues[i]) {
      if (const auto it = by_tissue.find(std::string(tissue_kind_name(*tissues[i])));
          it != by_tissue.end()) {
        s.material = it->second;
        continue;
      }
    }
    if (!fallback) {
      fail(ptr, "segment '" + s.name + "' gets no material: add a 'default' or a rule for it");
    }
    s.material = *fallback;
  }
}

ToolDescription Parser::parse_tool(const Json& j, const std::string& ptr) const {
  object(j, ptr, "a tool");
  allow_keys(j, ptr, {"name", "radius_m", "offset_m", "finger"});
  ToolDescription t;
  t.name = nonempty_string(required(j, ptr, "name"), at(ptr, "name"), "a tool name");
  t.radius_m = number_in(j, ptr, "radius_m", t.radius_m, 0.0, 0.1, "m");
  if (j.contains("offset_m")) {
    t.offset_device = vec3(j["offset_m"], at(ptr, "offset_m"), "m");
  }
  if (j.contains("finger")) {
    const std::string fp = at(ptr, "finger");
    const Json& f = j["finger"];
    if (!f.is_number_integer() || f.get<int>() < -1 || f.get<int>() >= kMaxFingers) {
      fail(fp, "expected -1 (the tip force) or a finger index 0.." +
                   std::to_string(kMaxFingers - 1) + ", got " + shown(f));
    }
    t.finger = f.get<int>();
  }
  return t;
}

void Parser::parse_device(const Json& j, const std::string& ptr, SceneDescription& scene) {
  object(j, ptr, "the device");
  allow_keys(j, ptr, {"type", "profile", "trajectory", "palpation", "hand", "glove_palpation"});
  DeviceDescription& d = scene.device;
  if (j.contains("type")) {
    d.type = one_of(j["type"], at(ptr, "type"), {"simulated", "glove"});
  }
  const bool glove = d.type == "glove";
  if (!glove && (j.contains("hand") || j.contains("glove_palpation"))) {
    fail(ptr, "'hand' and 'glove_palpation' need \"type\": \"glove\"");
  }
  if (glove) {
    scene.world.has_hand = true;
    if (j.contains("hand")) {
      const std::string hp = at(ptr, "hand");
      const Json& h = object(j["hand"], hp, "hand settings");
      allow_keys(h, hp, {"dip_per_pip"});
      scene.world.hand.dip_per_pip = number_in(h, hp, "dip_per_pip", 2.0 / 3.0, 0.0, 2.0, "");
    }
    for (std::size_t i = 0; i < scene.world.tools.size(); ++i) {
      if (scene.world.tools[i].finger < 0) {
        fail(at(at("/tools", i), "finger"),
             "a glove drives the tools: expected a finger 0 (thumb) .. 4 (little)");
      }
    }
    if (j.contains("palpation")) {
      fail(at(ptr, "palpation"), "a glove is scripted by 'glove_palpation'");
    }
  }
  if (j.contains("profile")) {
    d.profile = nonempty_string(j["profile"], at(ptr, "profile"), "a device profile name");
    const auto names = device_profile_names();
    if (std::find(names.begin(), names.end(), d.profile) == names.end()) {
      std::string list;
      for (const auto& n : names) {
        list += (list.empty() ? "" : ", ") + n;
      }
      fail(at(ptr, "profile"), "expected one of " + list + ", got '" + d.profile + "'");
    }
  }
  for (const ToolDescription& t : scene.world.tools) {
    if (t.finger >= 0 && t.finger >= device_profile(d.profile).finger_count) {
      fail(at(ptr, "profile"), "device '" + d.profile + "' has " +
                                   std::to_string(device_profile(d.profile).finger_count) +
                                   " finger actuator(s); tool '" + t.name + "' uses finger " +
                                   std::to_string(t.finger));
    }
  }
  const char* script = glove ? "glove_palpation" : "palpation";
  if (j.contains("trajectory") == j.contains(script)) {
    fail(ptr, std::string("expected exactly one of 'trajectory' (a CSV file) or '") + script +
                  "' (a script)");
  }
  if (j.contains("trajectory")) {
    d.trajectory_file = path(j["trajectory"], at(ptr, "trajectory"), "a trajectory CSV path");
    if (!std::filesystem::is_regular_file(d.trajectory_file)) {
      fail(at(ptr, "trajectory"), "no such file: " + d.trajectory_file.string());
    }
    return;
  }
  if (glove) {
    parse_glove_palpation(j["glove_palpation"], at(ptr, "glove_palpation"), scene);
    return;
  }
  const std::string pp = at(ptr, "palpation");
  const Json& p = object(j["palpation"], pp, "a palpation script");
  allow_keys(
      p, pp,
      {"standoff_m", "move_s", "approach_s", "press_s", "release_s", "around_axis", "targets"});
  d.has_palpation = true;
  PalpationScriptDescription& s = d.palpation;
  s.standoff_m = number_in(p, pp, "standoff_m", s.standoff_m, 0.0, 1.0, "m");
  s.move_s = number_in(p, pp, "move_s", s.move_s, 0.0, 60.0, "seconds", true);
  s.approach_s = number_in(p, pp, "approach_s", s.approach_s, 0.0, 60.0, "seconds", true);
  s.press_s = number_in(p, pp, "press_s", s.press_s, 0.0, 60.0, "seconds", true);
  s.release_s = number_in(p, pp, "release_s", s.release_s, 0.0, 60.0, "seconds", true);
  if (p.contains("around_axis")) {
    s.around_axis_world = vec3(p["around_axis"], at(pp, "around_axis"), "");
    if (!(s.around_axis_world.norm() > 1e-9)) {
      fail(at(pp, "around_axis"), "expected a non-zero direction (e.g. the limb's long axis)");
    }
    s.around_axis_world.normalize();
    s.has_around_axis = true;
  }
  const std::string tp = at(pp, "targets");
  const Json& targets = array(required(p, pp, "targets"), tp, "palpation targets");
  if (targets.empty()) {
    fail(tp, "expected at least one target");
  }
  for (std::size_t i = 0; i < targets.size(); ++i) {
    const std::string ip = at(tp, i);
    const Json& t = object(targets[i], ip, "a palpation target");
    allow_keys(t, ip, {"body", "segment", "from", "depth_m", "hold_s"});
    PalpationTargetDescription target;
    target.body = nonempty_string(required(t, ip, "body"), at(ip, "body"), "a body name");
    target.segment =
        nonempty_string(required(t, ip, "segment"), at(ip, "segment"), "a segment name");
    target.from_world = vec3(required(t, ip, "from"), at(ip, "from"), "");
    if (!(target.from_world.norm() > 1e-9)) {
      fail(at(ip, "from"), "expected a non-zero direction (from the segment towards the probe)");
    }
    target.from_world.normalize();
    target.depth_m = number_in(t, ip, "depth_m", target.depth_m, 0.0, 0.1, "m");
    target.hold_s = number_in(t, ip, "hold_s", target.hold_s, 0.0, 60.0, "seconds");
    s.targets.push_back(target);
  }
}

void Parser::parse_glove_palpation(const Json& j, const std::string& ptr,
                                   SceneDescription& scene) const {
  object(j, ptr, "a glove palpation script");
  allow_keys(
      j, ptr,
      {"fingers", "from", "depth_m", "standoff_m", "move_s", "press_s", "hold_s", "release_s"});
  DeviceDescription& d = scene.device;
  d.has_glove_palpation = true;
  GlovePalpationDescription& g = d.glove_palpation;
  g.from_world = vec3(required(j, ptr, "from"), at(ptr, "from"), "");
  if (!(g.from_world.norm() > 1e-9)) {
    fail(at(ptr, "from"), "expected a non-zero direction (from the body towards the hand)");
  }
  g.from_world.normalize();
  g.depth_m = number_in(j, ptr, "depth_m", g.depth_m, 0.0, 0.1, "m");
  g.standoff_m = number_in(j, ptr, "standoff_m", g.standoff_m, 0.0, 1.0, "m");
  g.move_s = number_in(j, ptr, "move_s", g.move_s, 0.0, 60.0, "seconds", true);
  g.press_s = number_in(j, ptr, "press_s", g.press_s, 0.0, 60.0, "seconds", true);
  g.hold_s = number_in(j, ptr, "hold_s", g.hold_s, 0.0, 60.0, "seconds");
  g.release_s = number_in(j, ptr, "release_s", g.release_s, 0.0, 60.0, "seconds", true);
  const std::string fp = at(ptr, "fingers");
  const Json& fingers = array(required(j, ptr, "fingers"), fp, "the pressing fingers");
  if (fingers.empty()) {
    fail(fp, "expected at least one finger");
  }
  std::set<int> seen;
  for (std::size_t i = 0; i < fingers.size(); ++i) {
    const std::string ip = at(fp, i);
    const Json& f = object(fingers[i], ip, "a finger target {finger, body, segment}");
    allow_keys(f, ip, {"finger", "body", "segment"});
    GloveFingerTarget t;
    const Json& n = required(f, ip, "finger");
    if (!n.is_number_integer() || n.get<int>() < 0 || n.get<int>() >= kHandFingers) {
      fail(at(ip, "finger"), "expected a finger 0 (thumb) .. 4 (little), got " + shown(n));
    }
    t.finger = n.get<int>();
    if (!seen.insert(t.finger).second) {
      fail(at(ip, "finger"), "finger " + std::to_string(t.finger) + " is listed twice");
    }
    if (std::none_of(scene.world.tools.begin(), scene.world.tools.end(),
                     [&](const ToolDescription& tool) { return tool.finger == t.finger; })) {
      fail(at(ip, "finger"), "no tool in /tools sits on finger " + std::to_string(t.finger));
    }
    t.body = nonempty_string(required(f, ip, "body"), at(ip, "body"), "a body name");
    t.segment = nonempty_string(required(f, ip, "segment"), at(ip, "segment"), "a segment name");
    const auto body = std::find_if(scene.world.bodies.begin(), scene.world.bodies.end(),
                                   [&](const BodyDescription& b) { return b.name == t.body; });
    if (body == scene.world.bodies.end()) {
      fail(at(ip, "body"), "expected the name of a body in /bodies, got '" + t.body + "'");
    }
    if (std::none_of(body->segments.begin(), body->segments.end(),
                     [&](const SegmentDescription& s) { return s.name == t.segment; })) {
      fail(at(ip, "segment"),
           "expected a segment of body '" + t.body + "', got '" + t.segment + "'");
    }
    g.fingers.push_back(t);
  }
}

void Parser::parse_run(const Json& root, SceneDescription& scene) const {
  if (root.contains("run")) {
    const Json& run = object(root["run"], "/run", "run settings");
    allow_keys(run, "/run", {"duration_s", "dt_s"});
    scene.run.duration_s = number_in(run, "/run", "duration_s", 0.0, 0.0, 86400.0, "seconds");
    scene.run.dt_s = number_in(run, "/run", "dt_s", 0.001, 0.0, 0.01, "seconds", true);
  }
}

void Parser::parse_teleop(const Json& j, const std::string& ptr, TeleopSceneDescription& t) {
  object(j, ptr, "teleoperation settings");
  allow_keys(j, ptr, {"slave", "mapping", "gripper", "ball", "sheet", "floor_z_m"});
  if (j.contains("slave")) {
    const std::string sp = at(ptr, "slave");
    const Json& s = object(j["slave"], sp, "the slave arm");
    allow_keys(s, sp, {"model", "urdf", "tip"});
    if (s.contains("model") == s.contains("urdf")) {
      fail(sp, "expected one of 'model' (\"procedural\") or 'urdf' (a URDF file)");
    }
    if (s.contains("model")) {
      one_of(s["model"], at(sp, "model"), {"procedural"});
    } else {
      t.slave_urdf = path(s["urdf"], at(sp, "urdf"), "a URDF file path");
      if (!std::filesystem::is_regular_file(t.slave_urdf)) {
        fail(at(sp, "urdf"), "no such file: " + t.slave_urdf.string());
      }
    }
    if (s.contains("tip")) {
      t.slave_tip = nonempty_string(s["tip"], at(sp, "tip"), "a link name");
    }
  }
  if (j.contains("mapping")) {
    const std::string mp = at(ptr, "mapping");
    const Json& m = object(j["mapping"], mp, "the master-to-slave mapping");
    allow_keys(m, mp, {"scale", "offset_m"});
    t.scale = number_in(m, mp, "scale", t.scale, 0.0, 100.0, "", true);
    if (m.contains("offset_m")) {
      t.offset_m = vec3(m["offset_m"], at(mp, "offset_m"), "m");
    }
  }
  if (j.contains("gripper")) {
    const std::string gp = at(ptr, "gripper");
    const Json& g = object(j["gripper"], gp, "gripper settings");
    allow_keys(g, gp, {"max_force_n", "max_width_m", "speed_m_per_s"});
    t.gripper_max_force_n =
        number_in(g, gp, "max_force_n", t.gripper_max_force_n, 0.0, 1000.0, "N", true);
    t.gripper_max_width_m =
        number_in(g, gp, "max_width_m", t.gripper_max_width_m, 0.0, 1.0, "m", true);
    t.gripper_speed_m_per_s =
        number_in(g, gp, "speed_m_per_s", t.gripper_speed_m_per_s, 0.0, 10.0, "m/s", true);
  }
  if (j.contains("ball")) {
    const std::string bp = at(ptr, "ball");
    const Json& b = object(j["ball"], bp, "ball settings");
    allow_keys(b, bp, {"mass_kg", "radius_m", "start_m"});
    t.ball_mass_kg = number_in(b, bp, "mass_kg", t.ball_mass_kg, 0.0, 100.0, "kg", true);
    t.ball_radius_m = number_in(b, bp, "radius_m", t.ball_radius_m, 0.0, 1.0, "m", true);
    if (b.contains("start_m")) {
      t.ball_start_m = vec3(b["start_m"], at(bp, "start_m"), "m");
    }
  }
  if (j.contains("sheet")) {
    const std::string shp = at(ptr, "sheet");
    const Json& sh = object(j["sheet"], shp, "sheet settings");
    allow_keys(sh, shp, {"nodes_per_side", "size_m", "position_m"});
    t.sheet_nodes_per_side = static_cast<int>(number_in(sh, shp, "nodes_per_side", 16, 2, 512, ""));
    t.sheet_size_m = number_in(sh, shp, "size_m", t.sheet_size_m, 0.0, 100.0, "m", true);
    if (sh.contains("position_m")) {
      t.sheet_position_m = vec3(sh["position_m"], at(shp, "position_m"), "m");
    }
  }
  t.floor_z_m = number_in(j, ptr, "floor_z_m", t.floor_z_m, -100.0, 100.0, "m");
}

void Parser::parse_teleop_device(const Json& j, const std::string& ptr, SceneDescription& scene) {
  object(j, ptr, "the master device");
  allow_keys(j, ptr, {"type", "trajectory", "pick_and_place"});
  DeviceDescription& d = scene.device;
  d.profile = "simulated";
  if (j.contains("type")) {
    d.type = one_of(j["type"], at(ptr, "type"), {"simulated"});
  }
  if (j.contains("trajectory") == j.contains("pick_and_place")) {
    fail(ptr,
         "expected exactly one of 'trajectory' (a CSV of master joints j0..j2 and fingers "
         "f0, f1) or 'pick_and_place' (a script)");
  }
  if (j.contains("trajectory")) {
    d.trajectory_file = path(j["trajectory"], at(ptr, "trajectory"), "a trajectory CSV path");
    if (!std::filesystem::is_regular_file(d.trajectory_file)) {
      fail(at(ptr, "trajectory"), "no such file: " + d.trajectory_file.string());
    }
    return;
  }
  const std::string pp = at(ptr, "pick_and_place");
  const Json& p = object(j["pick_and_place"], pp, "a pick-and-place script");
  allow_keys(p, pp, {"place_m", "clearance_m", "carry_s"});
  d.has_pick_and_place = true;
  PickAndPlaceDescription& s = d.pick_and_place;
  s.place_m = vec3(required(p, pp, "place_m"), at(pp, "place_m"), "m");
  s.clearance_m = number_in(p, pp, "clearance_m", s.clearance_m, 0.0, 1.0, "m", true);
  s.carry_s = number_in(p, pp, "carry_s", s.carry_s, 0.0, 60.0, "seconds", true);
}

// 1-based line and column of a byte offset, for JSON syntax errors.
std::string line_column(std::string_view text, std::size_t byte) {
  byte = std::min(byte, text.size());
  std::size_t line = 1;
  std::size_t column = 1;
  for (std::size_t i = 0; i < byte; ++i) {
    if (text[i] == '\n') {
      ++line;
      column = 1;
    } else {
      ++column;
    }
  }
  return std::to_string(line) + ":" + std::to_string(column);
}

}  // namespace

SceneDescription parse_scene(std::string_view json_text, const std::filesystem::path& file,
                             const SceneLoadOptions& options) {
  Json root;
  try {
    root = Json::parse(json_text.begin(), json_text.end());
  } catch (const Json::parse_error& e) {
    // e.byte is one past the offending character.
    const std::size_t byte = e.byte > 0 ? e.byte - 1 : 0;
    std::string what = e.what();
    if (const auto pos = what.find("syntax error"); pos != std::string::npos) {
      what = what.substr(pos);
    }
    throw Error(file.string() + ":" + line_column(json_text, byte), "invalid JSON: " + what);
  }
  return Parser(file, options).parse(root);
}

SceneDescription load_scene(const std::filesystem::path& file, const SceneLoadOptions& options) {
  std::ifstream in(file, std::ios::binary);
  if (!in || std::filesystem::is_directory(file)) {
    throw Error(file.string(), "cannot open the scene file (missing or unreadable)");
  }
  std::ostringstream text;
  text << in.rdbuf();
  return parse_scene(text.str(), file, options);
}

}  // namespace hapsim
