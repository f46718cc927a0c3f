#include "hapsim/scene/device_reader.h"

#include "hapsim/core/device_io.h"
#include "hapsim/core/device_profile.h"
#include "hapsim/scene/glove_calibration_file.h"

#include <algorithm>
#include <set>

namespace hapsim {
namespace {

using Json = JsonReader::Json;

void read_glove_palpation(const SceneReader& r, const Json& j, const std::string& ptr,
                          SceneDescription& scene) {
  r.object(j, ptr, "a glove palpation script");
  r.allow_keys(
      j, ptr,
      {"fingers", "from", "depth_m", "standoff_m", "move_s", "press_s", "hold_s", "release_s"});
  DeviceDescription& d = scene.device;
  d.has_glove_palpation = true;
  GlovePalpationDescription& g = d.glove_palpation;
  g.from_world = r.vec3(r.required(j, ptr, "from"), JsonReader::at(ptr, "from"), "");
  if (!(g.from_world.norm() > 1e-9)) {
    r.fail(JsonReader::at(ptr, "from"),
           "expected a non-zero direction (from the body towards the hand)");
  }
  g.from_world.normalize();
  g.depth_m = r.number_in(j, ptr, "depth_m", g.depth_m, 0.0, 0.1, "m");
  g.standoff_m = r.number_in(j, ptr, "standoff_m", g.standoff_m, 0.0, 1.0, "m");
  g.move_s = r.number_in(j, ptr, "move_s", g.move_s, 0.0, 60.0, "seconds", true);
  g.press_s = r.number_in(j, ptr, "press_s", g.press_s, 0.0, 60.0, "seconds", true);
  g.hold_s = r.number_in(j, ptr, "hold_s", g.hold_s, 0.0, 60.0, "seconds");
  g.release_s = r.number_in(j, ptr, "release_s", g.release_s, 0.0, 60.0, "seconds", true);
  const std::string fp = JsonReader::at(ptr, "fingers");
  const Json& fingers = r.array(r.required(j, ptr, "fingers"), fp, "the pressing fingers");
  if (fingers.empty()) {
    r.fail(fp, "expected at least one finger");
  }
  std::set<int> seen;
  for (std::size_t i = 0; i < fingers.size(); ++i) {
    const std::string ip = JsonReader::at(fp, i);
    const Json& f = r.object(fingers[i], ip, "a finger target {finger, body, segment}");
    r.allow_keys(f, ip, {"finger", "body", "segment", "toward_m"});
    GloveFingerTarget t;
    const Json& n = r.required(f, ip, "finger");
    if (!n.is_number_integer() || n.get<int>() < 0 || n.get<int>() >= kHandFingers) {
      r.fail(JsonReader::at(ip, "finger"),
             "expected a finger 0 (thumb) .. 4 (little), got " + JsonReader::shown(n));
    }
    t.finger = n.get<int>();
    if (!seen.insert(t.finger).second) {
      r.fail(JsonReader::at(ip, "finger"),
             "finger " + std::to_string(t.finger) + " is listed twice");
    }
    if (std::none_of(scene.world.tools.begin(), scene.world.tools.end(),
                     [&](const ToolDescription& tool) { return tool.finger == t.finger; })) {
      r.fail(JsonReader::at(ip, "finger"),
             "no tool in /tools sits on finger " + std::to_string(t.finger));
    }
    t.body =
        r.nonempty_string(r.required(f, ip, "body"), JsonReader::at(ip, "body"), "a body name");
    if (f.contains("toward_m")) {
      t.toward_world = r.vec3(f["toward_m"], JsonReader::at(ip, "toward_m"), "m");
    }
    if (f.contains("segment") || !t.toward_world) {
      t.segment = r.nonempty_string(r.required(f, ip, "segment"), JsonReader::at(ip, "segment"),
                                    "a segment name");
    }
    const auto body = std::find_if(scene.world.bodies.begin(), scene.world.bodies.end(),
                                   [&](const BodyDescription& b) { return b.name == t.body; });
    if (body == scene.world.bodies.end()) {
      r.fail(JsonReader::at(ip, "body"),
             "expected the name of a body in /bodies, got '" + t.body + "'");
    }
    if ((!t.segment.empty() || !t.toward_world) &&
        std::none_of(body->segments.begin(), body->segments.end(),
                     [&](const SegmentDescription& s) { return s.name == t.segment; })) {
      r.fail(JsonReader::at(ip, "segment"),
             "expected a segment of body '" + t.body + "', got '" + t.segment + "'");
    }
    g.fingers.push_back(t);
  }
}

void read_palpation(const SceneReader& r, const Json& j, const std::string& pp,
                    DeviceDescription& d) {
  const Json& p = r.object(j, pp, "a palpation script");
  r.allow_keys(
      p, pp,
      {"standoff_m", "move_s", "approach_s", "press_s", "release_s", "around_axis", "targets"});
  d.has_palpation = true;
  PalpationScriptDescription& s = d.palpation;
  s.standoff_m = r.number_in(p, pp, "standoff_m", s.standoff_m, 0.0, 1.0, "m");
  s.move_s = r.number_in(p, pp, "move_s", s.move_s, 0.0, 60.0, "seconds", true);
  s.approach_s = r.number_in(p, pp, "approach_s", s.approach_s, 0.0, 60.0, "seconds", true);
  s.press_s = r.number_in(p, pp, "press_s", s.press_s, 0.0, 60.0, "seconds", true);
  s.release_s = r.number_in(p, pp, "release_s", s.release_s, 0.0, 60.0, "seconds", true);
  if (p.contains("around_axis")) {
    s.around_axis_world = r.vec3(p["around_axis"], JsonReader::at(pp, "around_axis"), "");
    if (!(s.around_axis_world.norm() > 1e-9)) {
      r.fail(JsonReader::at(pp, "around_axis"),
             "expected a non-zero direction (e.g. the limb's long axis)");
    }
    s.around_axis_world.normalize();
    s.has_around_axis = true;
  }
  const std::string tp = JsonReader::at(pp, "targets");
  const Json& targets = r.array(r.required(p, pp, "targets"), tp, "palpation targets");
  if (targets.empty()) {
    r.fail(tp, "expected at least one target");
  }
  for (std::size_t i = 0; i < targets.size(); ++i) {
    const std::string ip = JsonReader::at(tp, i);
    const Json& t = r.object(targets[i], ip, "a palpation target");
    r.allow_keys(t, ip, {"body", "segment", "toward_m", "from", "depth_m", "hold_s"});
    PalpationTargetDescription target;
    target.body =
        r.nonempty_string(r.required(t, ip, "body"), JsonReader::at(ip, "body"), "a body name");
    if (t.contains("toward_m")) {
      target.toward_world = r.vec3(t["toward_m"], JsonReader::at(ip, "toward_m"), "m");
    }
    if (t.contains("segment") || !target.toward_world) {
      target.segment = r.nonempty_string(r.required(t, ip, "segment"),
                                         JsonReader::at(ip, "segment"), "a segment name");
    }
    target.from_world = r.vec3(r.required(t, ip, "from"), JsonReader::at(ip, "from"), "");
    if (!(target.from_world.norm() > 1e-9)) {
      r.fail(JsonReader::at(ip, "from"),
             "expected a non-zero direction (from the segment towards the probe)");
    }
    target.from_world.normalize();
    target.depth_m = r.number_in(t, ip, "depth_m", target.depth_m, 0.0, 0.1, "m");
    target.hold_s = r.number_in(t, ip, "hold_s", target.hold_s, 0.0, 60.0, "seconds");
    s.targets.push_back(target);
  }
}

void read_glove_pick_and_place(const SceneReader& r, const Json& j, const std::string& ptr,
                               SceneDescription& scene) {
  r.object(j, ptr, "a glove pick-and-place script");
  r.allow_keys(j, ptr,
               {"ball", "sheet", "place_m", "squeeze_m", "press_depth_m", "lift_m",
                "open_clearance_m", "approach_s", "close_s", "lift_s", "carry_s", "lower_s",
                "press_s", "open_s", "retreat_s", "settle_s"});
  DeviceDescription& d = scene.device;
  d.has_glove_pick_and_place = true;
  GlovePickAndPlaceDescription& g = d.glove_pick_and_place;
  g.ball = r.nonempty_string(r.required(j, ptr, "ball"), JsonReader::at(ptr, "ball"), "a body");
  g.sheet = r.nonempty_string(r.required(j, ptr, "sheet"), JsonReader::at(ptr, "sheet"), "a body");
  for (const auto& [key, name] : {std::pair{"ball", &g.ball}, std::pair{"sheet", &g.sheet}}) {
    const std::string* wanted = name;  // clang 14 cannot capture a structured binding
    if (std::none_of(scene.world.bodies.begin(), scene.world.bodies.end(),
                     [&](const BodyDescription& b) { return b.name == *wanted; })) {
      r.fail(JsonReader::at(ptr, key), "no body named '" + *name + "' in /bodies");
    }
  }
  if (j.contains("place_m")) {
    const std::string pp = JsonReader::at(ptr, "place_m");
    const Json& p = r.array(j["place_m"], pp, "[x, y] on the sheet, metres");
    if (p.size() != 2) {
      r.fail(pp, "expected [x, y] on the sheet, metres");
    }
    g.place_sheet = Vec3(r.number(p[0], JsonReader::at(pp, 0), "m"),
                         r.number(p[1], JsonReader::at(pp, 1), "m"), 0.0);
  }
  g.squeeze_m = r.number_in(j, ptr, "squeeze_m", g.squeeze_m, 0.0, 0.05, "m", true);
  g.press_depth_m = r.number_in(j, ptr, "press_depth_m", g.press_depth_m, 0.0, 0.2, "m");
  g.lift_m = r.number_in(j, ptr, "lift_m", g.lift_m, 0.0, 1.0, "m", true);
  g.open_clearance_m =
      r.number_in(j, ptr, "open_clearance_m", g.open_clearance_m, 0.0, 0.2, "m", true);
  for (const auto& [key, value] :
       {std::pair{"approach_s", &g.approach_s}, std::pair{"close_s", &g.close_s},
        std::pair{"lift_s", &g.lift_s}, std::pair{"carry_s", &g.carry_s},
        std::pair{"lower_s", &g.lower_s}, std::pair{"press_s", &g.press_s},
        std::pair{"open_s", &g.open_s}, std::pair{"retreat_s", &g.retreat_s},
        std::pair{"settle_s", &g.settle_s}}) {
    *value = r.number_in(j, ptr, key, *value, 0.0, 60.0, "seconds", true);
  }
  for (const int finger : {0, 1}) {
    if (std::none_of(scene.world.tools.begin(), scene.world.tools.end(),
                     [&](const ToolDescription& tool) { return tool.finger == finger; })) {
      r.fail(ptr, std::string("the pinch needs a tool on the ") +
                      (finger == 0 ? "thumb (finger 0)" : "index (finger 1)"));
    }
  }
}

// The device's "trajectory": a CSV path beside the scene file, which must exist unless the command
// plays another (--device sim:FILE).
void read_trajectory_file(const SceneReader& r, const Json& j, const std::string& ptr,
                          DeviceDescription& d) {
  const std::string tp = JsonReader::at(ptr, "trajectory");
  d.trajectory_file = r.options().device_trajectory_played
                          ? r.existing_file(j["trajectory"], tp, "a trajectory CSV path")
                          : r.path(j["trajectory"], tp, "a trajectory CSV path");
}

// A rig's device: the simulated master arm, played from a trajectory of its joints or scripted
// (a pick-and-place of the rig's ball, or a palpation carried by the slave's tool).
void read_rig_master(const SceneReader& r, const Json& j, const std::string& ptr,
                     DeviceDescription& d) {
  for (const char* key :
       {"profile", "calibration", "hand", "glove_palpation", "glove_pick_and_place"}) {
    if (j.contains(key)) {
      r.fail(JsonReader::at(ptr, key),
             "a rig's device is its simulated master arm: no '" + std::string(key) + "'");
    }
  }
  if (d.type != "simulated") {
    r.fail(JsonReader::at(ptr, "type"), "a rig's device is its master arm: \"simulated\"");
  }
  d.profile = "simulated";
  const int scripts = static_cast<int>(j.contains("trajectory")) +
                      static_cast<int>(j.contains("pick_and_place")) +
                      static_cast<int>(j.contains("palpation"));
  if (scripts != 1) {
    r.fail(ptr,
           "expected exactly one of 'trajectory' (a CSV of master joints j0..j2 and fingers f0, "
           "f1), 'pick_and_place' or 'palpation' (a script)");
  }
  if (j.contains("trajectory")) {
    read_trajectory_file(r, j, ptr, d);
    return;
  }
  if (j.contains("palpation")) {
    read_palpation(r, j["palpation"], JsonReader::at(ptr, "palpation"), d);
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

}  // namespace

void read_device(const SceneReader& r, const Json& j, const std::string& ptr,
                 SceneDescription& scene) {
  r.object(j, ptr, "the device");
  r.allow_keys(j, ptr,
               {"type", "profile", "trajectory", "calibration", "palpation", "hand",
                "glove_palpation", "glove_pick_and_place", "pick_and_place"});
  DeviceDescription& d = scene.device;
  if (j.contains("type")) {
    d.type = r.one_of(j["type"], JsonReader::at(ptr, "type"), {"simulated", "glove"});
  }
  const bool glove = d.type == "glove";
  if (scene.has_rig) {
    read_rig_master(r, j, ptr, d);
    return;
  }
  if (j.contains("pick_and_place")) {
    r.fail(JsonReader::at(ptr, "pick_and_place"),
           "a pick-and-place script moves a rig's master arm: the scene needs a \"rig\"");
  }
  if (!glove &&
      (j.contains("hand") || j.contains("glove_palpation") || j.contains("glove_pick_and_place"))) {
    r.fail(ptr, "'hand', 'glove_palpation' and 'glove_pick_and_place' need \"type\": \"glove\"");
  }
  if (j.contains("calibration")) {
    const std::string cp = JsonReader::at(ptr, "calibration");
    if (!glove) {
      r.fail(cp,
             "a calibration turns a glove's raw sensor counts into angles: it needs "
             "\"type\": \"glove\"");
    }
    if (!j.contains("trajectory")) {
      r.fail(cp,
             "a calibration applies to a 'trajectory' of raw sensor counts; the glove's "
             "scripts give joint angles");
    }
    d.glove_calibration_file =
        r.existing_file(j["calibration"], cp, "a glove calibration (USER.json)");
    // Read with the scene: a bad calibration is a load error, naming its own file and pointer.
    d.glove_calibration = load_glove_calibration(d.glove_calibration_file);
  }
  if (glove) {
    scene.world.has_hand = true;
    if (j.contains("hand")) {
      const std::string hp = JsonReader::at(ptr, "hand");
      const Json& h = r.object(j["hand"], hp, "hand settings");
      r.allow_keys(h, hp, {"dip_per_pip"});
      scene.world.hand.dip_per_pip = r.number_in(h, hp, "dip_per_pip", 2.0 / 3.0, 0.0, 2.0, "");
    }
    for (std::size_t i = 0; i < scene.world.tools.size(); ++i) {
      if (scene.world.tools[i].finger < 0) {
        r.fail(JsonReader::at(JsonReader::at("/tools", i), "finger"),
               "a glove drives the tools: expected a finger 0 (thumb) .. 4 (little)");
      }
    }
    if (j.contains("palpation")) {
      r.fail(JsonReader::at(ptr, "palpation"), "a glove is scripted by 'glove_palpation'");
    }
  }
  if (j.contains("profile")) {
    d.profile =
        r.nonempty_string(j["profile"], JsonReader::at(ptr, "profile"), "a device profile name");
    const auto names = device_profile_names();
    if (std::find(names.begin(), names.end(), d.profile) == names.end()) {
      std::string list;
      for (const auto& n : names) {
        list += (list.empty() ? "" : ", ") + n;
      }
      r.fail(JsonReader::at(ptr, "profile"),
             "expected one of " + list + ", got '" + d.profile + "'");
    }
  }
  for (const ToolDescription& t : scene.world.tools) {
    if (t.finger >= 0 && t.finger >= device_profile(d.profile).finger_count) {
      r.fail(JsonReader::at(ptr, "profile"),
             "device '" + d.profile + "' has " +
                 std::to_string(device_profile(d.profile).finger_count) +
                 " finger actuator(s); tool '" + t.name + "' uses finger " +
                 std::to_string(t.finger));
    }
  }
  const char* script = glove ? "glove_palpation" : "palpation";
  if (glove && j.contains("glove_pick_and_place")) {
    if (j.contains("trajectory") || j.contains("glove_palpation")) {
      r.fail(ptr,
             "expected exactly one of 'trajectory' (a CSV file), 'glove_palpation' or "
             "'glove_pick_and_place' (a script)");
    }
    read_glove_pick_and_place(r, j["glove_pick_and_place"],
                              JsonReader::at(ptr, "glove_pick_and_place"), scene);
    return;
  }
  if (j.contains("trajectory") == j.contains(script)) {
    r.fail(ptr, std::string("expected exactly one of 'trajectory' (a CSV file) or '") + script +
                    "' (a script)");
  }
  if (j.contains("trajectory")) {
    read_trajectory_file(r, j, ptr, d);
    return;
  }
  if (glove) {
    read_glove_palpation(r, j["glove_palpation"], JsonReader::at(ptr, "glove_palpation"), scene);
    return;
  }
  read_palpation(r, j["palpation"], JsonReader::at(ptr, "palpation"), d);
}

void check_palpation_targets(const SceneReader& r, const SceneDescription& scene) {
  if (!scene.device.has_palpation) {
    return;
  }
  for (std::size_t i = 0; i < scene.device.palpation.targets.size(); ++i) {
    const PalpationTargetDescription& t = scene.device.palpation.targets[i];
    const std::string p = JsonReader::at("/device/palpation/targets", i);
    const auto body = std::find_if(scene.world.bodies.begin(), scene.world.bodies.end(),
                                   [&](const BodyDescription& b) { return b.name == t.body; });
    if (body == scene.world.bodies.end()) {
      r.fail(JsonReader::at(p, "body"),
             "expected the name of a body in /bodies, got '" + t.body + "'");
    }
    if ((!t.segment.empty() || !t.toward_world) &&
        std::none_of(body->segments.begin(), body->segments.end(),
                     [&](const SegmentDescription& s) { return s.name == t.segment; })) {
      std::string names;
      for (std::size_t s = 0; s < body->segments.size() && s < 40; ++s) {
        names += (names.empty() ? "" : ", ") + body->segments[s].name;
      }
      r.fail(JsonReader::at(p, "segment"), "expected a segment of body '" + t.body + "' (" + names +
                                               "), got '" + t.segment + "'");
    }
  }
}

}  // namespace hapsim
