#include "hapsim/scene/teleop_dialect.h"

#include "hapsim/rig/ball_environment.h"
#include "hapsim/rig/rigid_ball.h"
#include "hapsim/scene/rig_reader.h"

#include <nlohmann/json.hpp>

namespace hapsim {

using Json = JsonReader::Json;

namespace {

// What an old "teleop" section says of the ball, the sheet and the floor (its defaults are the
// first paper's set-up, as scenes/teleop.json had it).
struct OldEnvironment {
  double ball_mass_kg = RigidBallParams{}.mass_kg;
  double ball_radius_m = RigidBallParams{}.radius_m;
  Vec3 ball_start_m = Vec3(0.5, -0.25, 0.03);
  int sheet_nodes_per_side = 16;
  double sheet_size_m = 0.2;
  Vec3 sheet_position_m = Vec3(0.5, 0.25, 0.05);
  double floor_z_m = 0.0;
};

OldEnvironment read_old_environment(const SceneReader& r, const Json& j, const std::string& ptr) {
  OldEnvironment e;
  if (j.contains("ball")) {
    const std::string bp = JsonReader::at(ptr, "ball");
    const Json& b = r.object(j["ball"], bp, "ball settings");
    r.allow_keys(b, bp, {"mass_kg", "radius_m", "start_m"});
    e.ball_mass_kg = r.number_in(b, bp, "mass_kg", e.ball_mass_kg, 0.0, 100.0, "kg", true);
    e.ball_radius_m = r.number_in(b, bp, "radius_m", e.ball_radius_m, 0.0, 1.0, "m", true);
    if (b.contains("start_m")) {
      e.ball_start_m = r.vec3(b["start_m"], JsonReader::at(bp, "start_m"), "m");
    }
  }
  if (j.contains("sheet")) {
    const std::string sp = JsonReader::at(ptr, "sheet");
    const Json& s = r.object(j["sheet"], sp, "sheet settings");
    r.allow_keys(s, sp, {"nodes_per_side", "size_m", "position_m"});
    e.sheet_nodes_per_side = static_cast<int>(r.number_in(s, sp, "nodes_per_side", 16, 2, 512, ""));
    e.sheet_size_m = r.number_in(s, sp, "size_m", e.sheet_size_m, 0.0, 100.0, "m", true);
    if (s.contains("position_m")) {
      e.sheet_position_m = r.vec3(s["position_m"], JsonReader::at(sp, "position_m"), "m");
    }
  }
  e.floor_z_m = r.number_in(j, ptr, "floor_z_m", e.floor_z_m, -100.0, 100.0, "m");
  return e;
}

Json vec3_json(const Vec3& v) {
  return Json::array({v.x(), v.y(), v.z()});
}

// A contact spring of the rig as a scene material: no penetration limit worth the name (a spring)
// and a force cap no contact of the rig reaches.
Json spring_material(const char* description, const ContactSpring& spring) {
  return {{"description", description},
          {"response", "penalty"},
          {"stiffness_n_per_m", spring.stiffness_n_per_m},
          {"damping_n_s_per_m", spring.damping_n_s_per_m},
          {"static_friction", spring.friction},
          {"dynamic_friction", spring.friction},
          {"max_penetration_m", 1.0},
          {"max_force_n", 1e4}};
}

}  // namespace

std::string teleop_dialect_note(const std::string& file) {
  return file +
         ": the \"teleop\" section is the older rig dialect, converted on read: its ball, sheet "
         "and floor are now ordinary bodies and the arm a \"rig\" that names them (write it so; "
         "scenes/teleop.json is the example, docs/scene-format.md#rigs)";
}

Json convert_teleop_scene(const SceneReader& r, const Json& root) {
  r.allow_keys(root, "",
               {"$schema", "format", "description", "data", "teleop", "device", "run", "views",
                "assessment"});
  const Json& old = r.object(root["teleop"], "/teleop", "teleoperation settings");
  r.allow_keys(old, "/teleop", {"slave", "mapping", "gripper", "ball", "sheet", "floor_z_m"});
  TeleopSceneDescription checked;
  read_rig_arm(r, old, "/teleop", checked);
  const OldEnvironment e = read_old_environment(r, old, "/teleop");

  Json scene = Json::object();
  for (const char* key :
       {"$schema", "format", "description", "data", "device", "run", "views", "assessment"}) {
    if (root.contains(key)) {
      scene[key] = root[key];
    }
  }
  const BallEnvironmentOptions environment;
  scene["world"] = {{"gravity_m_per_s2", vec3_json(RigidBallParams{}.gravity_m_per_s2)}};
  scene["materials"] = {
      {"ball",
       {{"description", "The ball is rigid: each of its contacts is the other body's spring."},
        {"response", "penalty"},
        {"rigid", true},
        {"max_penetration_m", 1.0},
        {"max_force_n", 1e4}}},
      {"sheet",
       spring_material("The ball's contact with the virtual sheet.", environment.sheet_contact)},
      {"floor", spring_material("The floor under the sheet.", environment.floor_contact)}};
  // The floor: the plane z = floor_z_m facing up, as a slab 2 m from the origin each way.
  const Vec3 floor_half_m(2.0, 2.0, 0.05);
  scene["bodies"] = Json::array(
      {{{"name", "floor"},
        {"type", "static"},
        {"pose", {{"position_m", vec3_json(Vec3(0.0, 0.0, e.floor_z_m - floor_half_m.z()))}}},
        {"geometry", {{"box", {{"half_extents_m", vec3_json(floor_half_m)}}}}},
        {"materials", "floor"}},
       {{"name", "sheet"},
        {"type", "deformable"},
        {"deformation", "sheet"},
        {"pose", {{"position_m", vec3_json(e.sheet_position_m)}}},
        {"geometry",
         {{"sheet", {{"nodes_per_side", e.sheet_nodes_per_side}, {"size_m", e.sheet_size_m}}}}},
        {"materials", "sheet"}},
       {{"name", "ball"},
        {"type", "dynamic"},
        {"mass_kg", e.ball_mass_kg},
        {"pose", {{"position_m", vec3_json(e.ball_start_m)}}},
        {"geometry", {{"sphere", {{"radius_m", e.ball_radius_m}, {"segments", 32}}}}},
        {"materials", "ball"}}});
  Json rig = {{"ball", "ball"}, {"sheet", "sheet"}, {"floor", "floor"}};
  for (const char* key : {"slave", "mapping", "gripper"}) {
    if (old.contains(key)) {
      rig[key] = old[key];
    }
  }
  scene["rig"] = std::move(rig);
  return scene;
}

}  // namespace hapsim
