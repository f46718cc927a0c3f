#include "hapsim/scene/assessment_reader.h"

#include <algorithm>
#include <set>

namespace hapsim {
namespace {

// The body holding segment `name` (the one named by `body`, else the only one with such a
// segment); an error at `ptr` otherwise.
std::string segment_body(const SceneReader& reader, const WorldDescription& world,
                         const std::string& body, const std::string& name, const std::string& ptr,
                         const std::string& body_ptr) {
  std::vector<std::string> holders;
  std::string all;
  for (const BodyDescription& b : world.bodies) {
    for (const SegmentDescription& s : b.segments) {
      if (all.size() < 400) {
        all += (all.empty() ? "" : ", ") + s.name;
      }
      if (s.name == name && (body.empty() || b.name == body)) {
        holders.push_back(b.name);
      }
    }
  }
  if (!body.empty() && std::none_of(world.bodies.begin(), world.bodies.end(),
                                    [&body](const BodyDescription& b) { return b.name == body; })) {
    reader.fail(body_ptr, "no body named '" + body + "'");
  }
  if (holders.empty()) {
    reader.fail(ptr, "no segment named '" + name + "'" + (body.empty() ? "" : " in body " + body) +
                         " (the segments: " + all + ")");
  }
  if (holders.size() > 1) {
    reader.fail(ptr, "segment '" + name + "' is in several bodies: give \"body\"");
  }
  return holders.front();
}

AssessmentLandmark read_landmark(const SceneReader& r, const JsonReader::Json& j,
                                 const std::string& ptr, const WorldDescription& world) {
  r.object(j, ptr, "a landmark {name, segment, force_n, dwell_s, point_m, radius_m}");
  r.allow_keys(j, ptr, {"name", "body", "segment", "point_m", "radius_m", "force_n", "dwell_s"});
  AssessmentLandmark l;
  l.name =
      r.nonempty_string(r.required(j, ptr, "name"), JsonReader::at(ptr, "name"), "a landmark name");
  const std::string body =
      j.contains("body") ? r.nonempty_string(j["body"], JsonReader::at(ptr, "body"), "a body name")
                         : std::string();
  l.segment = r.nonempty_string(r.required(j, ptr, "segment"), JsonReader::at(ptr, "segment"),
                                "a segment name");
  l.body = segment_body(r, world, body, l.segment, JsonReader::at(ptr, "segment"),
                        JsonReader::at(ptr, "body"));
  if (j.contains("radius_m") && !j.contains("point_m")) {
    r.fail(JsonReader::at(ptr, "radius_m"), "a radius needs a point_m to be around");
  }
  if (j.contains("point_m")) {
    l.point_world = r.vec3(j["point_m"], JsonReader::at(ptr, "point_m"), "m");
    if (!j.contains("radius_m")) {
      r.fail(JsonReader::at(ptr, "point_m"), "a point needs a radius_m (metres, > 0)");
    }
    l.radius_m = r.number_in(j, ptr, "radius_m", 0.0, 0.0, 1.0, "metres", true);
  }
  (void)r.required(j, ptr, "force_n");
  l.force_n = r.number_in(j, ptr, "force_n", 1.0, 0.0, 1000.0, "newtons", true);
  l.dwell_s = r.number_in(j, ptr, "dwell_s", 0.2, 0.0, 3600.0, "seconds");
  return l;
}

AssessmentLimit read_limit(const SceneReader& r, const JsonReader::Json& j, const std::string& ptr,
                           const WorldDescription& world) {
  r.object(j, ptr, "a force limit {segment | material, max_force_n}");
  r.allow_keys(j, ptr, {"body", "segment", "material", "max_force_n"});
  AssessmentLimit l;
  if (j.contains("segment") == j.contains("material")) {
    r.fail(ptr, "expected one of \"segment\" and \"material\" (the tissue the limit is for)");
  }
  if (j.contains("material")) {
    if (j.contains("body")) {
      r.fail(JsonReader::at(ptr, "body"), "a material's limit holds for every body: no \"body\"");
    }
    l.material =
        r.nonempty_string(j["material"], JsonReader::at(ptr, "material"), "a material name");
    if (std::none_of(world.materials.begin(), world.materials.end(),
                     [&l](const MaterialDescription& m) { return m.name == l.material; })) {
      std::string all;
      for (const MaterialDescription& m : world.materials) {
        all += (all.empty() ? "" : ", ") + m.name;
      }
      r.fail(JsonReader::at(ptr, "material"),
             "no material named '" + l.material + "' (the materials: " + all + ")");
    }
  } else {
    const std::string body =
        j.contains("body")
            ? r.nonempty_string(j["body"], JsonReader::at(ptr, "body"), "a body name")
            : std::string();
    l.segment = r.nonempty_string(j["segment"], JsonReader::at(ptr, "segment"), "a segment name");
    l.body = segment_body(r, world, body, l.segment, JsonReader::at(ptr, "segment"),
                          JsonReader::at(ptr, "body"));
  }
  (void)r.required(j, ptr, "max_force_n");
  l.max_force_n = r.number_in(j, ptr, "max_force_n", 0.0, 0.0, 1000.0, "newtons", true);
  return l;
}

}  // namespace

void read_assessment(const SceneReader& reader, const JsonReader::Json& j, const std::string& ptr,
                     SceneDescription& scene) {
  reader.object(j, ptr, "an assessment {landmarks, limits, time_limit_s}");
  reader.allow_keys(j, ptr, {"description", "landmarks", "limits", "time_limit_s"});
  AssessmentDefinition& a = scene.assessment;
  a = {};
  if (j.contains("description")) {
    (void)reader.string(j["description"], JsonReader::at(ptr, "description"), "a description");
  }
  if (j.contains("time_limit_s")) {
    a.time_limit_s = reader.number_in(j, ptr, "time_limit_s", 0.0, 0.0, 86400.0, "seconds", true);
  }
  if (j.contains("landmarks")) {
    const std::string lp = JsonReader::at(ptr, "landmarks");
    const JsonReader::Json& list = reader.array(j["landmarks"], lp, "a list of landmarks");
    std::set<std::string> names;
    for (std::size_t i = 0; i < list.size(); ++i) {
      a.landmarks.push_back(read_landmark(reader, list[i], JsonReader::at(lp, i), scene.world));
      if (!names.insert(a.landmarks.back().name).second) {
        reader.fail(
            JsonReader::at(JsonReader::at(lp, i), "name"),
            "expected a unique landmark name; '" + a.landmarks.back().name + "' is used twice");
      }
    }
  }
  if (j.contains("limits")) {
    const std::string lp = JsonReader::at(ptr, "limits");
    const JsonReader::Json& list = reader.array(j["limits"], lp, "a list of force limits");
    std::set<std::string> tissues;
    for (std::size_t i = 0; i < list.size(); ++i) {
      a.limits.push_back(read_limit(reader, list[i], JsonReader::at(lp, i), scene.world));
      if (!tissues.insert(a.limits.back().tissue()).second) {
        reader.fail(JsonReader::at(lp, i),
                    "expected one limit per tissue; '" + a.limits.back().tissue() + "' has two");
      }
    }
  }
  scene.has_assessment = true;
}

}  // namespace hapsim
