#include "hapsim/scene/scene_file.h"

#include "hapsim/core/device_io.h"
#include "hapsim/core/error.h"
#include "hapsim/core/text_file.h"
#include "hapsim/force/contact_material.h"
#include "hapsim/geometry/mass_properties.h"
#include "hapsim/scene/assessment_reader.h"
#include "hapsim/scene/device_reader.h"
#include "hapsim/scene/fem_reader.h"
#include "hapsim/scene/geometry_reader.h"
#include "hapsim/scene/json_text.h"
#include "hapsim/scene/rig_reader.h"
#include "hapsim/scene/scene_reader.h"
#include "hapsim/scene/teleop_dialect.h"
#include "hapsim/scene/view_reader.h"
#include "hapsim/world/fem_coupling.h"

#include <nlohmann/json.hpp>

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <map>
#include <optional>
#include <set>
#include <sstream>

namespace hapsim {
namespace {

using Json = nlohmann::json;

// Far above any scene (the knee_vhf scene is a few kB; meshes are files of their own).
constexpr std::size_t kMaxSceneFileBytes = std::size_t{64} << 20;

// The parser of the top level, materials, bodies, tools and run; the parts have their own readers
// (geometry_reader.h, device_reader.h, rig_reader.h, teleop_dialect.h). It carries the file name
// for messages, the folders paths resolve against (SceneReader), and the materials read so far for
// cross-references.
class Parser : public SceneReader {
 public:
  Parser(std::filesystem::path file, const SceneLoadOptions& options)
      : SceneReader(std::move(file), options), geometry_(*this) {}

  SceneDescription parse(const Json& root);

 private:
  void parse_materials(const Json& j, const std::string& ptr, WorldDescription& world);
  void parse_body(const Json& j, const std::string& ptr, WorldDescription& world);
  void parse_dynamics(const Json& j, const std::string& ptr, BodyDescription& body) const;
  void parse_deformation(const Json& j, const std::string& ptr, BodyDescription& body) const;
  /// FEM bodies: what they are attached to exists, and there are few enough of them.
  void check_fem_attachments(const WorldDescription& world) const;
  void parse_body_materials(const Json& j, const std::string& ptr, BodyDescription& body,
                            const std::vector<std::optional<TissueKind>>& tissues);
  ToolDescription parse_tool(const Json& j, const std::string& ptr) const;
  std::string device_host_name(const Json& tool, const std::string& ptr) const;
  void parse_run(const Json& root, SceneDescription& scene) const;
  std::uint32_t material_ref(const Json& j, const std::string& ptr) const;

  GeometryReader geometry_;
  std::map<std::string, std::uint32_t> material_index_;
};

SceneDescription Parser::parse(const Json& root) {
  object(root, "", "a scene");
  if (root.contains("teleop")) {
    // The older rig dialect: the same scene in the one language, with a note saying so.
    SceneDescription scene = parse(convert_teleop_scene(*this, root));
    scene.warnings.insert(scene.warnings.begin(), teleop_dialect_note(file_.string()));
    return scene;
  }
  allow_keys(root, "",
             {"$schema", "format", "description", "data", "world", "materials", "bodies", "tools",
              "rig", "device", "run", "views", "assessment"});
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
    set_data_default(nonempty_string(required(data, "/data", "default"), "/data/default",
                                     "a folder under the data root"));
  }
  scene.world.name = file_.stem().string();
  if (root.contains("world")) {
    const Json& w = object(root["world"], "/world", "world settings");
    allow_keys(w, "/world", {"name", "passivity_damping_factor", "gravity_m_per_s2"});
    if (w.contains("gravity_m_per_s2")) {
      scene.world.gravity_m_per_s2 =
          vec3(w["gravity_m_per_s2"], "/world/gravity_m_per_s2", "m/s^2");
      if (!(scene.world.gravity_m_per_s2.norm() <= 1000.0)) {
        fail("/world/gravity_m_per_s2", "expected at most 1000 m/s^2");
      }
    }
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
    report_progress(options().progress, "scene: bodies",
                    static_cast<double>(i) / static_cast<double>(bodies.size()));
    parse_body(bodies[i], at("/bodies", i), scene.world);
    if (!body_names.insert(scene.world.bodies.back().name).second) {
      fail(at(at("/bodies", i), "name"),
           "expected a unique body name; '" + scene.world.bodies.back().name + "' is used twice");
    }
  }
  check_fem_attachments(scene.world);
  scene.warnings = geometry_.warnings();
  for (const BodyDescription& body : scene.world.bodies) {
    if (!body.fem || body.segments.empty()) {
      continue;
    }
    // The coupling raises a patch too small for the surface's mesh (world/fem_coupling.h): say so.
    const double given_m = body.fem->contact_patch_radius_m;
    const double used_m = fem_patch_radius_m(given_m, body.segments[0].mesh);
    if (used_m > given_m) {
      char w[320];
      std::snprintf(w, sizeof w,
                    "body '%s': contact patch radius %.1f mm raised to %.1f mm (%.1fx the "
                    "surface's mean edge): a smaller patch holds one to three nodes and the force "
                    "ripples as the tool slides over them; a finer mesh keeps the smaller patch",
                    body.name.c_str(), given_m * 1e3, used_m * 1e3, kFemPatchEdges);
      scene.warnings.emplace_back(w);
    }
  }

  // A rig's device is its master arm, which drives the slave: the rig needs no tool.
  const Json no_tools = Json::array();
  const Json& tools = root.contains("rig") && !root.contains("tools")
                          ? no_tools
                          : array(required(root, "", "tools"), "/tools", "a list of tools");
  if (tools.empty() && !root.contains("rig")) {
    fail("/tools", "expected at least one tool (the device drives its tools)");
  }
  std::set<std::string> tool_names;
  std::set<std::pair<int, int>> fingers;  // (device, finger)
  // Several users: each tool names its device host; the hosts are numbered in the order they
  // first appear (the first is the device the scene's own script and `hapsim run` drive).
  std::vector<std::string>& hosts = scene.world.device_hosts;
  const auto named = [](const Json& t) { return t.is_object() && t.contains("device_host"); };
  const bool several_users = std::any_of(tools.begin(), tools.end(), named);
  for (std::size_t i = 0; i < tools.size(); ++i) {
    scene.world.tools.push_back(parse_tool(tools[i], at("/tools", i)));
    ToolDescription& t = scene.world.tools.back();
    if (!tool_names.insert(t.name).second) {
      fail(at(at("/tools", i), "name"),
           "expected a unique tool name; '" + t.name + "' is used twice");
    }
    if (several_users) {
      if (!named(tools[i])) {
        fail(at("/tools", i), "tool '" + t.name +
                                  "' names no device_host, while others do: name one for each "
                                  "tool (the device host that moves it)");
      }
      const std::string host = device_host_name(tools[i], at(at("/tools", i), "device_host"));
      auto it = std::find(hosts.begin(), hosts.end(), host);
      if (it == hosts.end()) {
        if (hosts.size() >= static_cast<std::size_t>(kMaxWorldDevices)) {
          fail(at(at("/tools", i), "device_host"),
               "expected at most " + std::to_string(kMaxWorldDevices) +
                   " device hosts in one world; '" + host + "' would be one more");
        }
        it = hosts.insert(hosts.end(), host);
      }
      t.device = static_cast<int>(it - hosts.begin());
    }
    if (t.finger >= 0 && !fingers.insert({t.device, t.finger}).second) {
      fail(at(at("/tools", i), "finger"),
           "expected each finger actuator to drive one tool; finger " + std::to_string(t.finger) +
               " is used twice");
    }
  }

  if (root.contains("rig")) {
    read_rig(*this, root["rig"], "/rig", scene);
  }
  read_device(*this, required(root, "", "device"), "/device", scene);

  parse_run(root, scene);
  // Palpation targets must name what exists.
  check_palpation_targets(*this, scene);
  if (root.contains("assessment")) {
    read_assessment(*this, root["assessment"], "/assessment", scene);
  }
  report_progress(options().progress, "scene: loaded", 1.0);
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
               {"description", "response", "rigid", "stiffness_n_per_m", "max_penetration_m",
                "max_force_n", "damping_n_s_per_m", "static_friction", "dynamic_friction",
                "deformation", "opacity"});
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
    if (m.contains("rigid") && boolean(m["rigid"], at(p, "rigid"))) {
      // A body that does not give: against another body the contact is the other's spring.
      for (const char* key : {"stiffness_n_per_m", "damping_n_s_per_m", "deformation"}) {
        if (m.contains(key)) {
          fail(at(p, key), "a rigid material has no " + std::string(key) +
                               ": against another body the contact is that body's spring");
        }
      }
      if (md.response != ContactResponse::kPenalty) {
        fail(at(p, "rigid"), "a rigid material needs \"response\": \"penalty\"");
      }
      c.stiffness_n_per_m = kRigidStiffness_n_per_m;
      c.damping_n_s_per_m = kRigidDamping_n_s_per_m;
    }
    c.static_friction = number_in(m, p, "static_friction", c.static_friction, 0.0, 10.0, "");
    c.dynamic_friction = number_in(m, p, "dynamic_friction", c.dynamic_friction, 0.0, 10.0, "");
    if (c.dynamic_friction > c.static_friction) {
      fail(at(p, "dynamic_friction"), "expected dynamic friction <= static friction (" +
                                          std::to_string(c.static_friction) + ")");
    }
    md.opacity = number_in(m, p, "opacity", 1.0, 0.0, 1.0, "", true);
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
  allow_keys(j, ptr,
             {"name", "type", "pose", "contact_method", "geometry", "materials", "mass_kg",
              "deformation", "sheet", "fem"});
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
  BodyGeometry geometry =
      geometry_.read(required(j, ptr, "geometry"), at(ptr, "geometry"), body.name);
  body.segments = std::move(geometry.segments);
  parse_body_materials(required(j, ptr, "materials"), at(ptr, "materials"), body, geometry.tissues);
  parse_dynamics(j, ptr, body);
  parse_deformation(j, ptr, body);
  const bool fem = body.deformation == BodyDeformation::kFem;
  if (fem != static_cast<bool>(geometry.tets)) {
    fail(at(ptr, fem ? "geometry" : "deformation"),
         fem ? "a FEM body needs a volume: the \"tet_block\" or \"tet_mesh\" geometry"
             : "a tet_block or tet_mesh geometry is a volume for \"deformation\": \"fem\"");
  }
  if (j.contains("fem") && !fem) {
    fail(at(ptr, "fem"), "FEM settings need \"deformation\": \"fem\"");
  }
  if (fem) {
    body.fem = std::make_shared<const FemBodyDescription>(
        read_fem_settings(*this, j.contains("fem") ? &j["fem"] : nullptr, at(ptr, "fem"),
                          *geometry.tets, geometry.embedded_surface, geometry.tets_source));
  }
  world.bodies.push_back(std::move(body));
}

void Parser::check_fem_attachments(const WorldDescription& world) const {
  std::size_t fem_bodies = 0;
  for (std::size_t b = 0; b < world.bodies.size(); ++b) {
    const BodyDescription& body = world.bodies[b];
    if (!body.fem) {
      continue;
    }
    if (++fem_bodies > kMaxFemBodies) {
      fail(at("/bodies", b), "more than " + std::to_string(kMaxFemBodies) +
                                 " FEM bodies in one scene (the coupling carries that many)");
    }
    for (std::size_t a = 0; a < body.fem->attached_to.size(); ++a) {
      const FemAttachment& att = body.fem->attached_to[a];
      const std::string ptr = at(at(at(at(at("/bodies", b), "fem"), "fixed"), "attached_to"), a);
      const auto other = std::find_if(world.bodies.begin(), world.bodies.end(),
                                      [&](const BodyDescription& o) { return o.name == att.body; });
      if (other == world.bodies.end() || &*other == &body) {
        fail(at(ptr, "body"), other == world.bodies.end()
                                  ? "no body named '" + att.body + "' in /bodies"
                                  : "a FEM body cannot be attached to itself");
      }
      if (!att.segment.empty() &&
          std::none_of(other->segments.begin(), other->segments.end(),
                       [&](const SegmentDescription& s) { return s.name == att.segment; })) {
        fail(at(ptr, "segment"), "body '" + att.body + "' has no segment '" + att.segment + "'");
      }
    }
  }
}

// A dynamic body's mass; its centre of mass and inertia follow from its shape at uniform density
// (a sphere's exactly: 2/5·m·r² about its centre).
void Parser::parse_dynamics(const Json& j, const std::string& ptr, BodyDescription& body) const {
  if (body.kind != BodyKind::kDynamic) {
    if (j.contains("mass_kg")) {
      fail(at(ptr, "mass_kg"), "only a \"dynamic\" body has a mass");
    }
    return;
  }
  if (!j.contains("mass_kg")) {
    fail(ptr, "a dynamic body needs 'mass_kg'");
  }
  RigidBodyDescription& r = body.rigid;
  r.mass_kg = number_in(j, ptr, "mass_kg", 0.0, 0.0, 10000.0, "kg", true);
  if (body.segments.size() == 1 && body.segments.front().sphere) {
    const ExactSphere& s = *body.segments.front().sphere;
    r.com_body = s.center_body;
    r.inertia_kg_m2 = Mat3::Identity() * 0.4 * r.mass_kg * s.radius_m * s.radius_m;
    return;
  }
  TriangleMesh all;
  for (const SegmentDescription& s : body.segments) {
    const auto first = static_cast<std::uint32_t>(all.vertices.size());
    all.vertices.insert(all.vertices.end(), s.mesh.vertices.begin(), s.mesh.vertices.end());
    for (const TriangleIndices& t : s.mesh.triangles) {
      all.triangles.push_back({t[0] + first, t[1] + first, t[2] + first});
    }
  }
  try {
    const MassProperties m = mass_properties(all);
    r.com_body = m.com;
    r.inertia_kg_m2 = m.inertia_per_density * (r.mass_kg / m.volume_m3);
  } catch (const Error& e) {
    fail(at(ptr, "geometry"), std::string("a dynamic body needs a closed shape: ") + e.what());
  }
}

// How a deformable body deforms: vertex deflection, or the virtual sheet (its sheet geometry's
// grid, with the Gaussian profile of "sheet").
void Parser::parse_deformation(const Json& j, const std::string& ptr, BodyDescription& body) const {
  const std::string how =
      j.contains("deformation")
          ? one_of(j["deformation"], at(ptr, "deformation"), {"deflection", "sheet", "fem"})
          : std::string("deflection");
  const bool sheet = how == "sheet";
  if (j.contains("deformation") && body.kind != BodyKind::kDeformable) {
    fail(at(ptr, "deformation"), "only a \"deformable\" body has a deformation");
  }
  if (how == "fem") {
    if (j.contains("sheet")) {
      fail(at(ptr, "sheet"), "sheet settings need \"deformation\": \"sheet\"");
    }
    body.deformation = BodyDeformation::kFem;
    return;
  }
  if (j.contains("sheet") && !sheet) {
    fail(at(ptr, "sheet"), "sheet settings need \"deformation\": \"sheet\"");
  }
  if (!sheet) {
    return;
  }
  const auto nodes = static_cast<int>(
      std::lround(std::sqrt(static_cast<double>(body.segments.front().mesh.vertex_count()))));
  if (body.segments.size() != 1 || !body.segments.front().two_sided ||
      static_cast<std::size_t>(nodes) * static_cast<std::size_t>(nodes) !=
          body.segments.front().mesh.vertex_count()) {
    fail(at(ptr, "geometry"), "a sheet body needs the \"sheet\" geometry");
  }
  body.deformation = BodyDeformation::kGaussianSheet;
  body.sheet.nodes_per_side = nodes;
  body.sheet.side_m = body.segments.front().mesh.bounds().sizes().x();
  if (j.contains("sheet")) {
    const std::string sp = at(ptr, "sheet");
    const Json& s = object(j["sheet"], sp, "sheet settings");
    allow_keys(s, sp, {"cutoff_radius_mm", "width_mm", "sensitivity_n_per_mm", "max_depth_m"});
    body.sheet_profile = GaussianSheetParams::from_mm(
        number_in(s, sp, "cutoff_radius_mm", 44.0, 0.0, 10000.0, "mm", true),
        number_in(s, sp, "width_mm", 40.1, 0.0, 10000.0, "mm", true),
        number_in(s, sp, "sensitivity_n_per_mm", 3.0, 0.0, 1e6, "N/mm", true));
    body.sheet.max_depth_m = number_in(s, sp, "max_depth_m", kInf, 0.0, 100.0, "m", true);
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
      by_name.emplace_back(ascii_lower(text),
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
    const std::string name = ascii_lower(s.name);
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
  allow_keys(j, ptr, {"name", "radius_m", "offset_m", "finger", "device_host"});
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

// A device host's name (`hapsim device --name NAME`): letters, digits, '-' and '_', 1-32 long.
std::string Parser::device_host_name(const Json& tool, const std::string& ptr) const {
  const std::string name = nonempty_string(tool["device_host"], ptr, "a device host's name");
  const bool plain =
      name.size() <= 32 && std::all_of(name.begin(), name.end(), [](char c) {
        return std::isalnum(static_cast<unsigned char>(c)) != 0 || c == '-' || c == '_';
      });
  if (!plain) {
    fail(ptr, "expected a device host's name of letters, digits, '-' and '_' (at most 32), got " +
                  shown(tool["device_host"]));
  }
  return name;
}

void Parser::parse_run(const Json& root, SceneDescription& scene) const {
  if (root.contains("views")) {
    scene.views = read_views(*this, root["views"], "/views");
  }
  if (root.contains("run")) {
    const Json& run = object(root["run"], "/run", "run settings");
    allow_keys(run, "/run", {"duration_s", "dt_s"});
    scene.run.duration_s = number_in(run, "/run", "duration_s", 0.0, 0.0, 86400.0, "seconds");
    scene.run.dt_s = number_in(run, "/run", "dt_s", 0.001, 0.0, 0.01, "seconds", true);
  }
}

}  // namespace

SceneDescription parse_scene(std::string_view json_text, const std::filesystem::path& file,
                             const SceneLoadOptions& options) {
  const Json root = parse_json_text(json_text, file.string());
  return Parser(file, options).parse(root);
}

SceneDescription load_scene(const std::filesystem::path& file, const SceneLoadOptions& options) {
  return parse_scene(read_text_file(file, kMaxSceneFileBytes, "scene file"), file, options);
}

}  // namespace hapsim
