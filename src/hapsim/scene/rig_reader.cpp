#include "hapsim/scene/rig_reader.h"

#include <algorithm>

namespace hapsim {

using Json = JsonReader::Json;

void read_rig_arm(const SceneReader& r, const Json& j, const std::string& ptr,
                  TeleopSceneDescription& t) {
  if (j.contains("slave")) {
    const std::string sp = JsonReader::at(ptr, "slave");
    const Json& s = r.object(j["slave"], sp, "the slave arm");
    r.allow_keys(s, sp, {"model", "urdf", "tip", "max_joint_acceleration_per_s2"});
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
    t.slave_max_acceleration_per_s2 =
        r.number_in(s, sp, "max_joint_acceleration_per_s2", t.slave_max_acceleration_per_s2, 0.0,
                    1e4, "rad/s²", true);
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

namespace {

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
  read_rig_arm(r, j, ptr, t);
  t.force_scale = r.number_in(j, ptr, "force_scale", t.force_scale, 0.0, 100.0, "");
  const WorldDescription& w = scene.world;
  t.ball_body = rig_body_name(r, j, ptr, "ball", w, BodyKind::kDynamic, "dynamic (a sphere)");
  if (!t.ball_body.empty()) {
    // The gripper closes to its radius and the pick-and-place aims at its centre.
    const auto ball = std::find_if(w.bodies.begin(), w.bodies.end(),
                                   [&](const BodyDescription& b) { return b.name == t.ball_body; });
    if (ball->segments.size() != 1 || !ball->segments.front().sphere) {
      r.fail(JsonReader::at(ptr, "ball"),
             "body '" + t.ball_body + "' must be a sphere (geometry \"sphere\"): the gripper " +
                 "closes to its radius");
    }
  }
  t.sheet_body = rig_body_name(r, j, ptr, "sheet", w, BodyKind::kDeformable, "a sheet");
  if (!t.sheet_body.empty()) {
    const auto sheet =
        std::find_if(w.bodies.begin(), w.bodies.end(),
                     [&](const BodyDescription& b) { return b.name == t.sheet_body; });
    if (sheet->deformation != BodyDeformation::kGaussianSheet) {
      r.fail(JsonReader::at(ptr, "sheet"), "body '" + t.sheet_body +
                                               "' must be a sheet (\"deformation\": \"sheet\"): "
                                               "the rig reports its deepest dent");
    }
  }
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

}  // namespace hapsim
