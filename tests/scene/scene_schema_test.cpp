// scenes/scene.schema.json stays true to the loader: the shipped scenes and a small valid scene
// satisfy it, and bad scenes that a schema can express are refused by both the schema and the
// loader. The schema is checked by a small JSON Schema (draft 2020-12) validator written here for
// the keywords the file uses; it refuses any other keyword, so the schema cannot quietly grow
// beyond what is checked. (Debian's python3-jsonschema agrees, but CI does not install it.)
#include "hapsim/core/device_profile.h"
#include "hapsim/core/error.h"
#include "hapsim/scene/scene_file.h"

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <functional>
#include <regex>
#include <set>
#include <string>

namespace hapsim {
namespace {

namespace fs = std::filesystem;
using Json = nlohmann::json;

const fs::path kScenes = fs::path(HAPSIM_SOURCE_DIR) / "scenes";

Json read_json(const fs::path& p) {
  std::ifstream in(p);
  return Json::parse(in);
}

// Returns the first violation as "<instance pointer>: <why>", or "" when `instance` is valid.
class SchemaValidator {
 public:
  explicit SchemaValidator(Json root) : root_(std::move(root)) {}

  std::string validate(const Json& instance) const { return check(root_, instance, ""); }

 private:
  const Json& resolve(const std::string& ref) const {
    const std::string prefix = "#/$defs/";
    if (ref.rfind(prefix, 0) != 0) {
      throw std::runtime_error("unsupported $ref " + ref);
    }
    return root_.at("$defs").at(ref.substr(prefix.size()));
  }

  static bool has_type(const Json& j, const std::string& type) {
    if (type == "object")
      return j.is_object();
    if (type == "array")
      return j.is_array();
    if (type == "string")
      return j.is_string();
    if (type == "boolean")
      return j.is_boolean();
    if (type == "number")
      return j.is_number();
    if (type == "integer") {
      return j.is_number_integer() ||
             (j.is_number_float() && std::floor(j.get<double>()) == j.get<double>());
    }
    throw std::runtime_error("unsupported type " + type);
  }

  std::string check(const Json& schema, const Json& j, const std::string& at) const {
    static const std::set<std::string> annotations = {"$schema",     "$id",     "title",
                                                      "description", "default", "$defs"};
    for (const auto& [key, value] : schema.items()) {
      if (annotations.count(key) != 0) {
        continue;
      }
      std::string why;
      if (key == "$ref") {
        why = check(resolve(value.get<std::string>()), j, at);
        if (!why.empty())
          return why;
        continue;
      }
      if (key == "type") {
        if (!has_type(j, value.get<std::string>()))
          why = "not " + value.get<std::string>();
      } else if (key == "const") {
        if (j != value)
          why = "not " + value.dump();
      } else if (key == "enum") {
        if (std::find(value.begin(), value.end(), j) == value.end())
          why = "not in " + value.dump();
      } else if (key == "minimum") {
        if (j.is_number() && j.get<double>() < value.get<double>())
          why = "below minimum";
      } else if (key == "maximum") {
        if (j.is_number() && j.get<double>() > value.get<double>())
          why = "above maximum";
      } else if (key == "exclusiveMinimum") {
        if (j.is_number() && j.get<double>() <= value.get<double>())
          why = "not above minimum";
      } else if (key == "minLength") {
        if (j.is_string() && j.get<std::string>().size() < value.get<std::size_t>())
          why = "short";
      } else if (key == "pattern") {
        if (j.is_string() &&
            !std::regex_search(j.get<std::string>(), std::regex(value.get<std::string>()))) {
          why = "does not match " + value.get<std::string>();
        }
      } else if (key == "minItems") {
        if (j.is_array() && j.size() < value.get<std::size_t>())
          why = "too few items";
      } else if (key == "maxItems") {
        if (j.is_array() && j.size() > value.get<std::size_t>())
          why = "too many items";
      } else if (key == "items") {
        if (j.is_array()) {
          for (std::size_t i = 0; i < j.size() && why.empty(); ++i) {
            const std::string w = check(value, j[i], at + "/" + std::to_string(i));
            if (!w.empty())
              return w;
          }
        }
      } else if (key == "minProperties") {
        if (j.is_object() && j.size() < value.get<std::size_t>())
          why = "too few properties";
      } else if (key == "required") {
        if (j.is_object()) {
          for (const Json& r : value) {
            if (!j.contains(r.get<std::string>()))
              why = "missing " + r.get<std::string>();
          }
        }
      } else if (key == "properties") {
        if (j.is_object()) {
          for (const auto& [name, sub] : value.items()) {
            if (j.contains(name)) {
              const std::string w = check(sub, j.at(name), at + "/" + name);
              if (!w.empty())
                return w;
            }
          }
        }
      } else if (key == "additionalProperties") {
        if (j.is_object()) {
          const Json* props = schema.contains("properties") ? &schema.at("properties") : nullptr;
          for (const auto& [name, sub] : j.items()) {
            if (props != nullptr && props->contains(name))
              continue;
            if (value.is_boolean()) {
              if (!value.get<bool>())
                return at + "/" + name + ": additional property";
            } else {
              const std::string w = check(value, sub, at + "/" + name);
              if (!w.empty())
                return w;
            }
          }
        }
      } else if (key == "propertyNames") {
        if (j.is_object()) {
          for (const auto& [name, sub] : j.items()) {
            const std::string w = check(value, Json(name), at + "/" + name);
            if (!w.empty())
              return w;
          }
        }
      } else if (key == "oneOf") {
        int passing = 0;
        for (const Json& option : value) {
          passing += check(option, j, at).empty() ? 1 : 0;
        }
        if (passing != 1)
          why = "matches " + std::to_string(passing) + " of oneOf, not 1";
      } else if (key == "anyOf") {
        bool any = false;
        for (const Json& option : value) {
          any = any || check(option, j, at).empty();
        }
        if (!any)
          why = "matches none of anyOf";
      } else if (key == "not") {
        if (check(value, j, at).empty())
          why = "matches a 'not'";
      } else {
        throw std::runtime_error("keyword '" + key +
                                 "' is used by the schema but not checked here");
      }
      if (!why.empty()) {
        return (at.empty() ? "/" : at) + ": " + why;
      }
    }
    return "";
  }

  Json root_;
};

SchemaValidator schema() {
  return SchemaValidator(read_json(kScenes / "scene.schema.json"));
}

Json small_scene() {
  return Json::parse(R"({
    "format": "hapsim-scene/1",
    "data": { "default": "somewhere" },
    "world": { "name": "w", "passivity_damping_factor": 1 },
    "materials": { "hard": { "stiffness_n_per_m": 2000, "static_friction": 0.3,
                             "dynamic_friction": 0.2,
                             "deformation": { "max_recovery_speed_m_per_s": "inf" } } },
    "bodies": [
      { "name": "block", "type": "deformable", "contact_method": "spheretree",
        "pose": { "position_m": [0, 0, 0], "rotation_deg": [0, 0, 90] },
        "geometry": { "box": { "half_extents_m": [0.02, 0.02, 0.02] } },
        "materials": { "default": "hard", "segments": { "block": "hard" },
                       "by_name": [ { "contains": "bl", "material": "hard" } ] } }
    ],
    "tools": [ { "name": "tip", "radius_m": 0.005, "offset_m": [0, 0, 0], "finger": -1 } ],
    "device": { "type": "simulated", "profile": "omega3",
                "palpation": { "around_axis": [0, 0, 1], "targets": [
                  { "body": "block", "segment": "block", "from": [0, 0, 1], "depth_m": 0.005 } ] } },
    "run": { "duration_s": 1, "dt_s": 0.001 }
  })");
}

TEST(SceneSchema, ShippedScenesAndASmallSceneSatisfyIt) {
  const SchemaValidator v = schema();
  for (const char* name :
       {"knee_paper.json", "knee_procedural.json", "knee_vhf.json", "knee_hand_procedural.json",
        "knee_hand.json", "teleop.json", "teleop_gp7.json", "csg_block.json",
        "hand_ball_sheet.json", "fem_block.json", "knee.json", "knee_hand_paper.json",
        "knee_fem_80k.json", "knee_fem_five_fingers.json", "thin_plate.json"}) {
    EXPECT_EQ(v.validate(read_json(kScenes / name)), "") << name;
  }
  EXPECT_EQ(v.validate(small_scene()), "");
  // The loader takes the small scene too (it has no data: paths, so the data folder is unused).
  const fs::path file = fs::temp_directory_path() / "hapsim_schema_small_scene.json";
  std::ofstream(file) << small_scene().dump();
  EXPECT_NO_THROW((void)load_scene(file));
  fs::remove(file);
}

// The small scene with its block as a CSG solid using every kind of node.
Json small_csg_scene() {
  Json j = small_scene();
  j["bodies"][0]["geometry"] = Json::parse(R"({ "resolution_m": 0.002, "csg": { "difference": [
      { "union": [ { "box": { "half_extents_m": [0.02, 0.02, 0.02] } },
                   { "cone": { "radius_m": 0.01, "height_m": 0.01 },
                     "pose": { "position_m": [0, 0, 0.02] } } ] },
      { "intersection": [ { "cylinder": { "radius_m": 0.005, "half_height_m": 0.03 } },
                          { "sphere": { "radius_m": 0.025 } } ] },
      { "torus": { "major_radius_m": 0.02, "minor_radius_m": 0.003 },
        "pose": { "rotation_deg": [90, 0, 0] } } ] } })");
  return j;
}

TEST(SceneSchema, ACsgSceneSatisfiesIt) {
  EXPECT_EQ(schema().validate(small_csg_scene()), "");
  const fs::path file = fs::temp_directory_path() / "hapsim_schema_csg_scene.json";
  std::ofstream(file) << small_csg_scene().dump();
  EXPECT_NO_THROW((void)load_scene(file));
  fs::remove(file);
}

TEST(SceneSchema, BadCsgScenesAreRefusedByTheSchemaAndTheLoader) {
  struct Case {
    const char* name;
    std::function<void(Json&)> change;
  };
  Json& (*csg)(Json&) = [](Json& j) -> Json& { return j["bodies"][0]["geometry"]["csg"]; };
  const Case cases[] = {
      {"unknown solid kind",
       [&](Json& j) {
         csg(j) = {{"pyramid", {{"radius_m", 0.01}}}};
       }},
      {"two kinds in a node",
       [&](Json& j) {
         csg(j)["difference"][2]["sphere"] = {{"radius_m", 0.01}};
       }},
      {"one-child list", [&](Json& j) { csg(j)["difference"][0]["union"].erase(1); }},
      {"empty list", [&](Json& j) { csg(j)["difference"][1]["intersection"] = Json::array(); }},
      {"zero radius",
       [&](Json& j) { csg(j)["difference"][1]["intersection"][1]["sphere"]["radius_m"] = 0; }},
      {"negative half extent",
       [&](Json& j) { csg(j)["difference"][0]["union"][0]["box"]["half_extents_m"][1] = -0.02; }},
      {"misspelt key", [&](Json& j) { csg(j)["difference"][2]["torus"]["minor_radius"] = 0.003; }},
      {"bad node pose", [&](Json& j) { csg(j)["difference"][2]["pose"]["scale"] = 2; }},
      {"zero resolution", [](Json& j) { j["bodies"][0]["geometry"]["resolution_m"] = 0; }},
  };
  const SchemaValidator v = schema();
  const fs::path file = fs::temp_directory_path() / "hapsim_schema_bad_csg_scene.json";
  for (const Case& c : cases) {
    SCOPED_TRACE(c.name);
    Json scene = small_csg_scene();
    c.change(scene);
    EXPECT_NE(v.validate(scene), "") << "the schema accepts it";
    std::ofstream(file) << scene.dump();
    EXPECT_THROW((void)load_scene(file), Error) << "the loader accepts it";
  }
  fs::remove(file);
}

TEST(SceneSchema, ProfilesAreTheBuiltInOnes) {
  const Json profiles =
      read_json(kScenes / "scene.schema.json")["$defs"]["device"]["properties"]["profile"]["enum"];
  std::vector<std::string> names;
  for (const Json& p : profiles) {
    names.push_back(p.get<std::string>());
  }
  EXPECT_EQ(names, device_profile_names());
}

TEST(SceneSchema, BadScenesAreRefusedByTheSchemaAndTheLoader) {
  struct Case {
    const char* name;
    std::function<void(Json&)> change;
  };
  const Case cases[] = {
      {"unknown root key", [](Json& j) { j["bodys"] = 1; }},
      {"wrong format", [](Json& j) { j["format"] = "hapsim-scene/2"; }},
      {"no materials", [](Json& j) { j["materials"] = Json::object(); }},
      {"misspelt material key", [](Json& j) { j["materials"]["hard"]["stifness_n_per_m"] = 1; }},
      {"stiffness as text", [](Json& j) { j["materials"]["hard"]["stiffness_n_per_m"] = "1"; }},
      {"zero stiffness", [](Json& j) { j["materials"]["hard"]["stiffness_n_per_m"] = 0; }},
      {"unknown response", [](Json& j) { j["materials"]["hard"]["response"] = "spring"; }},
      {"negative max deflection",
       [](Json& j) { j["materials"]["hard"]["deformation"]["max_deflection_m"] = -1; }},
      {"no bodies", [](Json& j) { j["bodies"] = Json::array(); }},
      {"unknown body type", [](Json& j) { j["bodies"][0]["type"] = "soft"; }},
      {"both rotations",
       [](Json& j) {
         j["bodies"][0]["pose"]["quaternion_wxyz"] = {1, 0, 0, 0};
       }},
      {"two geometry kinds",
       [](Json& j) {
         j["bodies"][0]["geometry"]["sphere"] = {{"radius_m", 0.01}};
       }},
      {"no geometry kind", [](Json& j) { j["bodies"][0]["geometry"] = Json::object(); }},
      {"two-number extents",
       [](Json& j) {
         j["bodies"][0]["geometry"]["box"]["half_extents_m"] = {1, 1};
       }},
      {"bad pattern",
       [](Json& j) {
         j["bodies"][0]["geometry"] = {{"mesh_folder", {{"folder", "."}, {"pattern", "stl"}}}};
       }},
      {"unknown tissue",
       [](Json& j) {
         j["bodies"][0]["materials"]["by_tissue"] = {{"fat", "hard"}};
       }},
      {"material as a number", [](Json& j) { j["bodies"][0]["materials"] = 3; }},
      {"no tools", [](Json& j) { j["tools"] = Json::array(); }},
      {"finger 5", [](Json& j) { j["tools"][0]["finger"] = 5; }},
      {"fractional finger", [](Json& j) { j["tools"][0]["finger"] = 0.5; }},
      {"unknown profile", [](Json& j) { j["device"]["profile"] = "phantom"; }},
      {"both trajectory and palpation", [](Json& j) { j["device"]["trajectory"] = "t.csv"; }},
      {"neither trajectory nor palpation", [](Json& j) { j["device"].erase("palpation"); }},
      {"target without from",
       [](Json& j) { j["device"]["palpation"]["targets"][0].erase("from"); }},
      {"zero time step", [](Json& j) { j["run"]["dt_s"] = 0; }},
      {"time step too long", [](Json& j) { j["run"]["dt_s"] = 0.02; }},
  };
  const SchemaValidator v = schema();
  const fs::path file = fs::temp_directory_path() / "hapsim_schema_bad_scene.json";
  for (const Case& c : cases) {
    SCOPED_TRACE(c.name);
    Json scene = small_scene();
    c.change(scene);
    EXPECT_NE(v.validate(scene), "") << "the schema accepts it";
    std::ofstream(file) << scene.dump();
    EXPECT_THROW((void)load_scene(file), Error) << "the loader accepts it";
  }
  fs::remove(file);
}

// The first paper's scenes/teleop.json as it was before the "rig" key (the older dialect, which
// still loads: converted on read; tests/data/teleop_older_dialect.json).
Json older_teleop_scene() {
  return read_json(fs::path(HAPSIM_SOURCE_DIR) / "tests" / "data" / "teleop_older_dialect.json");
}

TEST(SceneSchema, TheOlderTeleopDialectIsStillAValidScene) {
  const Json old = older_teleop_scene();
  EXPECT_EQ(schema().validate(old), "");
  const fs::path file = fs::temp_directory_path() / "hapsim_schema_older_teleop.json";
  std::ofstream(file) << old.dump();
  EXPECT_TRUE(load_scene(file).has_rig);
  fs::remove(file);
}

// The slave's acceleration limit: 30 rad/s² unless the scene says, and what it says is read.
TEST(SceneSchema, TheSlavesAccelerationLimitIsReadWithItsDefault) {
  const fs::path file = fs::temp_directory_path() / "hapsim_schema_slave_acceleration.json";
  Json scene = read_json(kScenes / "teleop.json");
  std::ofstream(file) << scene.dump();
  EXPECT_EQ(load_scene(file).teleop.slave_max_acceleration_per_s2, 30.0);
  scene["rig"]["slave"]["max_joint_acceleration_per_s2"] = 12.5;
  EXPECT_EQ(schema().validate(scene), "");
  std::ofstream(file) << scene.dump();
  EXPECT_EQ(load_scene(file).teleop.slave_max_acceleration_per_s2, 12.5);
  fs::remove(file);
}

// The rig scene's own mistakes: a rigid material with a stiffness, a rig naming a tool that is not
// there, a world with neither tools nor a rig.
TEST(SceneSchema, BadRigScenesAreRefusedByTheSchemaAndTheLoader) {
  struct Case {
    const char* name;
    std::function<void(Json&)> change;
  };
  const Case cases[] = {
      {"rigid is not a boolean", [](Json& j) { j["materials"]["ball"]["rigid"] = "yes"; }},
      {"neither tools nor a rig", [](Json& j) { j.erase("rig"); }},
      {"unknown rig key", [](Json& j) { j["rig"]["robot"] = "gp7"; }},
      {"a slave that cannot accelerate",
       [](Json& j) { j["rig"]["slave"]["max_joint_acceleration_per_s2"] = 0; }},
      {"a ball named by position",
       [](Json& j) {
         j["rig"]["ball"] = {0.5, 0.1, 0.0};
       }},
  };
  const SchemaValidator v = schema();
  const Json rig = read_json(kScenes / "teleop.json");
  const fs::path file = fs::temp_directory_path() / "hapsim_schema_bad_rig.json";
  for (const Case& c : cases) {
    SCOPED_TRACE(c.name);
    Json scene = rig;
    c.change(scene);
    EXPECT_NE(v.validate(scene), "") << "the schema accepts it";
    std::ofstream(file) << scene.dump();
    EXPECT_THROW((void)load_scene(file), Error) << "the loader accepts it";
  }
  // Said by the loader alone: a rigid material has no stiffness of its own.
  Json stiff = rig;
  stiff["materials"]["ball"]["stiffness_n_per_m"] = 5000;
  std::ofstream(file) << stiff.dump();
  EXPECT_THROW((void)load_scene(file), Error);
  fs::remove(file);
}

TEST(SceneSchema, BadTeleopScenesAreRefusedByTheSchemaAndTheLoader) {
  struct Case {
    const char* name;
    std::function<void(Json&)> change;
  };
  const Case cases[] = {
      {"teleop and bodies", [](Json& j) { j["bodies"] = Json::array(); }},
      {"unknown teleop key", [](Json& j) { j["teleop"]["robot"] = "gp7"; }},
      {"both slave kinds", [](Json& j) { j["teleop"]["slave"]["urdf"] = "gp7.urdf"; }},
      {"unknown slave model", [](Json& j) { j["teleop"]["slave"]["model"] = "kuka"; }},
      {"zero scale", [](Json& j) { j["teleop"]["mapping"]["scale"] = 0; }},
      {"negative ball mass", [](Json& j) { j["teleop"]["ball"]["mass_kg"] = -0.1; }},
      {"two-number ball start",
       [](Json& j) {
         j["teleop"]["ball"]["start_m"] = {0.5, 0.1};
       }},
      {"one-node sheet", [](Json& j) { j["teleop"]["sheet"]["nodes_per_side"] = 1; }},
      {"no place", [](Json& j) { j["device"]["pick_and_place"].erase("place_m"); }},
      {"script and trajectory", [](Json& j) { j["device"]["trajectory"] = "m.csv"; }},
      {"palpation in a teleop scene",
       [](Json& j) {
         j["device"].erase("pick_and_place");
         j["device"]["palpation"] = {{"targets", Json::array()}};
       }},
  };
  const SchemaValidator v = schema();
  const Json teleop = older_teleop_scene();
  const fs::path file = fs::temp_directory_path() / "hapsim_schema_bad_teleop.json";
  for (const Case& c : cases) {
    SCOPED_TRACE(c.name);
    Json scene = teleop;
    c.change(scene);
    EXPECT_NE(v.validate(scene), "") << "the schema accepts it";
    std::ofstream(file) << scene.dump();
    EXPECT_THROW((void)load_scene(file), Error) << "the loader accepts it";
  }
  fs::remove(file);
}

}  // namespace
}  // namespace hapsim
