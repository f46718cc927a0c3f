#include "hapsim/scene/teleop_reader.h"

#include <algorithm>

namespace hapsim {

using Json = JsonReader::Json;

namespace {

// The parts a "teleop" and a "rig" section share: the slave, the mapping, the gripper.
void read_arm(const SceneReader& r, const Json& j, const std::string& ptr,
              TeleopSceneDescription& t) {
  if (j.contains("slave")) {
    const std::string sp = JsonReader::at(ptr, "slave");
    const Json& s = r.object(j["slave"], sp, "the slave arm");
    r.allow_keys(s, sp, {"model", "urdf", "tip"});
    if (s.contains("model") == s.contains("urdf")) {
      r.fail(sp, "expected one of 'model' (\"procedural\") or 'urdf' (a URDF file)");
    }
    if (s.contains("model")) {
      r.one_of(s["model"], JsonReader::at(sp, "model"), {"procedural"});
    } else {
      t.slave_urdf = r.path(s["urdf"], JsonReader::at(sp, "urdf"), "a URDF file path");
      std::error_code ec;
      if (!std::filesystem::is_regular_file(t.slave_urdf, ec)) {
        r.fail(JsonReader::at(sp, "urdf"), "no such file: " + t.slave_urdf.string());
      }
    }
    if (s.contains("tip")) {
      t.slave_tip = r.nonempty_string(s["tip"], JsonReader::at(sp, "tip"), "a link name");
    }
  }
  if (j.contains("mapping")) {
    const std::string mp = JsonReader::at(ptr, "mapping");
    const Json& m = r.object(j["mapping"], mp, "the master-to-slave mapping");
    r.allow_keys(m, mp, {"scale", "offset_m"});
    t.scale = r.number_in(m, mp, "scale", t.scale, 0.0, 100.0, "", true);
    if (m.contains("offset_m")) {
      t.offset_m = r.vec3(m["offset_m"], JsonReader::at(mp, "offset_m"), "m");
    }
  }
  if (j.contains("gripper")) {
    const std::string gp = JsonReader::at(ptr, "gripper");
    const Json& g = r.object(j["gripper"], gp, "gripper settings");
    r.allow_keys(g, gp, {"max_force_n", "max_width_m", "speed_m_per_s"});
    t.gripper_max_force_n =
        r.number_in(g, gp, "max_force_n", t.gripper_max_force_n, 0.0, 1000.0, "N", true);
    t.gripper_max_width_m =
        r.number_in(g, gp, "max_width_m", t.gripper_max_width_m, 0.0, 1.0, "m", true);
    t.gripper_speed_m_per_s =
        r.number_in(g, gp, "speed_m_per_s", t.gripper_speed_m_per_s, 0.0, 10.0, "m/s", true);
  }
}

// A body named in a rig section: one of the scene's, of the kind the rig needs.
std::string rig_body_name(const SceneReader& r, const Json& j, const std::string& ptr,
                          const char* key, const WorldDescription& world, BodyKind kind,
                          const char* what) {
  if (!j.contains(key)) {
    return {};
  }
  const std::string p = JsonReader::at(ptr, key);
  std::string name = r.nonempty_string(j[key], p, "a body name");
  const auto it = std::find_if(world.bodies.begin(), world.bodies.end(),
                               [&](const BodyDescription& b) { return b.name == name; });
  if (it == world.bodies.end()) {
    r.fail(p, "no body named '" + name + "' in /bodies");
  }
  if (it->kind != kind) {
    r.fail(p, "body '" + name + "' must be " + what);
  }
  return name;
}

}  // namespace

void read_rig(const SceneReader& r, const Json& j, const std::string& ptr,
              SceneDescription& scene) {
  TeleopSceneDescription& t = scene.teleop;
  r.object(j, ptr, "the rig");
  r.allow_keys(
      j, ptr,
      {"slave", "mapping", "gripper", "force_scale", "carries_tool", "ball", "sheet", "floor"});
  read_arm(r, j, ptr, t);
  t.force_scale = r.number_in(j, ptr, "force_scale", t.force_scale, 0.0, 100.0, "");
  const WorldDescription& w = scene.world;
  t.ball_body = rig_body_name(r, j, ptr, "ball", w, BodyKind::kDynamic, "dynamic (a sphere)");
  t.sheet_body = rig_body_name(r, j, ptr, "sheet", w, BodyKind::kDeformable, "a sheet");
  t.floor_body = rig_body_name(r, j, ptr, "floor", w, BodyKind::kStatic, "static");
  if (j.contains("carries_tool")) {
    const std::string p = JsonReader::at(ptr, "carries_tool");
    t.carried_tool = r.nonempty_string(j["carries_tool"], p, "a tool name");
    const auto it = std::find_if(w.tools.begin(), w.tools.end(), [&](const ToolDescription& tool) {
      return tool.name == t.carried_tool;
    });
    if (it == w.tools.end()) {
      r.fail(p, "no tool named '" + t.carried_tool + "' in /tools");
    }
    if (it->finger >= 0 || it->device != 0) {
      r.fail(p, "tool '" + t.carried_tool + "' must be the first device's, with no finger");
    }
  }
  scene.has_rig = true;
}

void read_teleop(const SceneReader& r, const Json& j, const std::string& ptr,
                 TeleopSceneDescription& t) {
  r.object(j, ptr, "teleoperation settings");
  r.allow_keys(j, ptr, {"slave", "mapping", "gripper", "ball", "sheet", "floor_z_m"});
  read_arm(r, j, ptr, t);
  if (j.contains("ball")) {
    const std::string bp = JsonReader::at(ptr, "ball");
    const Json& b = r.object(j["ball"], bp, "ball settings");
    r.allow_keys(b, bp, {"mass_kg", "radius_m", "start_m"});
    t.ball_mass_kg = r.number_in(b, bp, "mass_kg", t.ball_mass_kg, 0.0, 100.0, "kg", true);
    t.ball_radius_m = r.number_in(b, bp, "radius_m", t.ball_radius_m, 0.0, 1.0, "m", true);
    if (b.contains("start_m")) {
      t.ball_start_m = r.vec3(b["start_m"], JsonReader::at(bp, "start_m"), "m");
    }
  }
  if (j.contains("sheet")) {
    const std::string shp = JsonReader::at(ptr, "sheet");
    const Json& sh = r.object(j["sheet"], shp, "sheet settings");
    r.allow_keys(sh, shp, {"nodes_per_side", "size_m", "position_m"});
    t.sheet_nodes_per_side =
        static_cast<int>(r.number_in(sh, shp, "nodes_per_side", 16, 2, 512, ""));
    t.sheet_size_m = r.number_in(sh, shp, "size_m", t.sheet_size_m, 0.0, 100.0, "m", true);
    if (sh.contains("position_m")) {
      t.sheet_position_m = r.vec3(sh["position_m"], JsonReader::at(shp, "position_m"), "m");
    }
  }
  t.floor_z_m = r.number_in(j, ptr, "floor_z_m", t.floor_z_m, -100.0, 100.0, "m");
}

void read_teleop_device(const SceneReader& r, const Json& j, const std::string& ptr,
                        DeviceDescription& d) {
  r.object(j, ptr, "the master device");
  r.allow_keys(j, ptr, {"type", "trajectory", "pick_and_place"});
  d.profile = "simulated";
  if (j.contains("type")) {
    d.type = r.one_of(j["type"], JsonReader::at(ptr, "type"), {"simulated"});
  }
  if (j.contains("trajectory") == j.contains("pick_and_place")) {
    r.fail(ptr,
           "expected exactly one of 'trajectory' (a CSV of master joints j0..j2 and fingers "
           "f0, f1) or 'pick_and_place' (a script)");
  }
  if (j.contains("trajectory")) {
    // Not needed when the command plays another (--device sim:FILE).
    const std::string tp = JsonReader::at(ptr, "trajectory");
    d.trajectory_file = r.options().device_trajectory_played
                            ? r.existing_file(j["trajectory"], tp, "a trajectory CSV path")
                            : r.path(j["trajectory"], tp, "a trajectory CSV path");
    return;
  }
  const std::string pp = JsonReader::at(ptr, "pick_and_place");
  const Json& p = r.object(j["pick_and_place"], pp, "a pick-and-place script");
  r.allow_keys(p, pp, {"place_m", "clearance_m", "carry_s"});
  d.has_pick_and_place = true;
  PickAndPlaceDescription& s = d.pick_and_place;
  s.place_m = r.vec3(r.required(p, pp, "place_m"), JsonReader::at(pp, "place_m"), "m");
  s.clearance_m = r.number_in(p, pp, "clearance_m", s.clearance_m, 0.0, 1.0, "m", true);
  s.carry_s = r.number_in(p, pp, "carry_s", s.carry_s, 0.0, 60.0, "seconds", true);
}

}  // namespace hapsim
