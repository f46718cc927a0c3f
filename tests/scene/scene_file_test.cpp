// Scene files: every bad input names the file and the JSON path (or line:column for broken JSON)
// and says what was expected; good files give exactly the world they describe; the shipped scenes
// load. The expected paths and fragments are written from docs/scene-format.md, not read back
// from the parser.
#include "hapsim/scene/scene_file.h"

#include "hapsim/core/error.h"
#include "hapsim/geometry/triangle_mesh.h"
#include "hapsim/scene/teleop_setup.h"
#include "hapsim/world/world.h"

#include "support/temp_dir_test.h"
#include "support/test_data.h"

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <unistd.h>
#include <cctype>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <functional>
#include <map>
#include <string>

namespace hapsim {
namespace {

namespace fs = std::filesystem;
using Json = nlohmann::json;

// A folder of its own per test binary run, removed at the end.
class SceneFileTest : public test::TempDirTest {
 protected:
  // A small valid scene: a rigid block, a deformable ball beside it, one probe on a desktop
  // stylus, a one-press palpation of the block from above.
  static Json base() {
    return Json::parse(R"({
      "format": "hapsim-scene/1",
      "materials": {
        "hard": { "response": "proxy", "stiffness_n_per_m": 2000, "static_friction": 0.3,
                  "dynamic_friction": 0.2 },
        "soft": { "response": "penalty", "stiffness_n_per_m": 300,
                  "deformation": { "elasticity_factor": 1.5, "max_deflection_m": "inf" } }
      },
      "bodies": [
        { "name": "block", "geometry": { "box": { "half_extents_m": [0.02, 0.02, 0.02] } },
          "materials": "hard" },
        { "name": "ball", "type": "deformable", "pose": { "position_m": [0.1, 0, 0] },
          "geometry": { "sphere": { "radius_m": 0.03, "segments": 32 } }, "materials": "soft" }
      ],
      "tools": [ { "name": "tip", "radius_m": 0.005 } ],
      "device": { "profile": "touch",
                  "palpation": { "targets": [ { "body": "block", "segment": "block",
                                                "from": [0, 0, 2] } ] } }
    })");
  }

  // Loads `scene` from a file in the test folder; expects an Error whose where() is
  // "<file>:<where_suffix>" and whose message holds `fragment`.
  void expect_error(const Json& scene, const std::string& where_suffix, const std::string& fragment,
                    const SceneLoadOptions& options = {}) const {
    expect_text_error(scene.dump(2), where_suffix, fragment, options);
  }

  void expect_text_error(const std::string& text, const std::string& where_suffix,
                         const std::string& fragment, const SceneLoadOptions& options = {}) const {
    const fs::path file = write("scene.json", text);
    try {
      (void)load_scene(file, options);
      ADD_FAILURE() << "loaded without error; expected " << where_suffix << ": " << fragment;
    } catch (const Error& e) {
      EXPECT_EQ(e.where(), file.string() + ":" + where_suffix) << e.what();
      EXPECT_NE(e.detail().find(fragment), std::string::npos)
          << "message: " << e.detail() << "\nexpected to contain: " << fragment;
      // The full text a user sees names both.
      EXPECT_NE(std::string(e.what()).find(file.string()), std::string::npos) << e.what();
    }
  }
};

struct Mutation {
  const char* name;
  std::function<void(Json&)> change;
  const char* where;
  const char* fragment;
};

TEST_F(SceneFileTest, BaseSceneLoadsExactlyAsWritten) {
  const SceneDescription s = load_scene(write("scene.json", base().dump()));
  ASSERT_EQ(s.world.materials.size(), 2u);
  ASSERT_EQ(s.world.bodies.size(), 2u);
  const MaterialDescription& hard = s.world.materials[s.world.bodies[0].segments[0].material];
  EXPECT_EQ(hard.name, "hard");
  EXPECT_EQ(hard.response, ContactResponse::kProxy);
  EXPECT_EQ(hard.contact.stiffness_n_per_m, 2000.0);
  EXPECT_EQ(hard.contact.dynamic_friction, 0.2);
  const MaterialDescription& soft = s.world.materials[s.world.bodies[1].segments[0].material];
  EXPECT_EQ(soft.name, "soft");
  EXPECT_EQ(soft.response, ContactResponse::kPenalty);
  EXPECT_TRUE(std::isinf(soft.deflection.max_deflection_m));
  EXPECT_EQ(soft.deflection.elasticity_factor, 1.5);

  const BodyDescription& block = s.world.bodies[0];
  EXPECT_EQ(block.kind, BodyKind::kStatic);  // the default
  EXPECT_EQ(block.method, ContactMethod::kExact);
  ASSERT_EQ(block.segments.size(), 1u);
  EXPECT_EQ(block.segments[0].name, "block");  // a single-shape body's segment takes its name
  const Box3 box = block.segments[0].mesh.bounds();
  EXPECT_NEAR(box.max().x(), 0.02, 1e-12);
  EXPECT_NEAR(box.min().z(), -0.02, 1e-12);

  const BodyDescription& ball = s.world.bodies[1];
  EXPECT_EQ(ball.kind, BodyKind::kDeformable);
  EXPECT_TRUE(ball.X_world_body.translation().isApprox(Vec3(0.1, 0, 0)));
  EXPECT_NEAR(ball.segments[0].mesh.bounds().max().z(), 0.03, 1e-9);

  ASSERT_EQ(s.world.tools.size(), 1u);
  EXPECT_EQ(s.world.tools[0].radius_m, 0.005);
  EXPECT_EQ(s.world.tools[0].finger, -1);
  EXPECT_EQ(s.device.profile, "touch");
  ASSERT_TRUE(s.device.has_palpation);
  ASSERT_EQ(s.device.palpation.targets.size(), 1u);
  // Directions are normalised.
  EXPECT_TRUE(s.device.palpation.targets[0].from_world.isApprox(Vec3::UnitZ()));
  EXPECT_FALSE(s.device.palpation.has_around_axis);
  EXPECT_EQ(s.run.dt_s, 0.001);
  EXPECT_EQ(s.run.duration_s, 0.0);
  EXPECT_EQ(s.world.name, "scene");  // the file's stem when /world/name is absent
}

// Several users in one world: each tool names the device host that moves it; hosts are numbered
// in the order they first appear, and one-user scenes keep their content hash.
TEST_F(SceneFileTest, ToolsBoundToNamedDeviceHostsGetTheirDeviceIndex) {
  const SceneDescription one = load_scene(write("one.json", base().dump()));
  EXPECT_TRUE(one.world.device_hosts.empty());
  EXPECT_EQ(one.world.tools[0].device, 0);
  Json j = base();
  j["tools"][0]["device_host"] = "trainee";
  j["tools"].push_back({{"name", "probe"}, {"device_host", "instructor"}});
  j["tools"].push_back({{"name", "second"}, {"device_host", "trainee"}});
  const SceneDescription s = load_scene(write("two.json", j.dump()));
  EXPECT_EQ(s.world.device_hosts, (std::vector<std::string>{"trainee", "instructor"}));
  ASSERT_EQ(s.world.tools.size(), 3u);
  EXPECT_EQ(s.world.tools[0].device, 0);
  EXPECT_EQ(s.world.tools[1].device, 1);
  EXPECT_EQ(s.world.tools[2].device, 0);
  EXPECT_NE(content_hash(s.world), content_hash(one.world));
  Json swapped = j;
  swapped["tools"][1]["device_host"] = "trainee";
  swapped["tools"][2]["device_host"] = "instructor";
  EXPECT_NE(content_hash(load_scene(write("swapped.json", swapped.dump())).world),
            content_hash(s.world));
}

TEST_F(SceneFileTest, EveryBadValueNamesItsJsonPath) {
  const Mutation cases[] = {
      {"missing format", [](Json& j) { j.erase("format"); }, "/", "missing required key 'format'"},
      {"wrong format", [](Json& j) { j["format"] = "hapsim-scene/2"; }, "/format",
       "expected \"hapsim-scene/1\""},
      {"unknown root key", [](Json& j) { j["bodys"] = Json::array(); }, "/bodys",
       "unknown key 'bodys'"},
      {"missing materials", [](Json& j) { j.erase("materials"); }, "/",
       "missing required key 'materials'"},
      {"no materials", [](Json& j) { j["materials"] = Json::object(); }, "/materials",
       "at least one material"},
      {"materials not an object", [](Json& j) { j["materials"] = Json::array(); }, "/materials",
       "a JSON object), got an array"},
      {"misspelt material key", [](Json& j) { j["materials"]["hard"]["stifness_n_per_m"] = 1; },
       "/materials/hard/stifness_n_per_m", "unknown key 'stifness_n_per_m'"},
      {"stiffness as text", [](Json& j) { j["materials"]["hard"]["stiffness_n_per_m"] = "300"; },
       "/materials/hard/stiffness_n_per_m", "expected a number in N/m, got a string"},
      {"negative stiffness", [](Json& j) { j["materials"]["hard"]["stiffness_n_per_m"] = -1; },
       "/materials/hard/stiffness_n_per_m", "expected a number > 0"},
      {"zero max force", [](Json& j) { j["materials"]["hard"]["max_force_n"] = 0; },
       "/materials/hard/max_force_n", "expected a number > 0"},
      {"infinite stiffness", [](Json& j) { j["materials"]["hard"]["stiffness_n_per_m"] = "inf"; },
       "/materials/hard/stiffness_n_per_m", "expected a number"},
      {"dynamic above static friction",
       [](Json& j) { j["materials"]["hard"]["dynamic_friction"] = 0.5; },
       "/materials/hard/dynamic_friction", "dynamic friction <= static friction"},
      {"unknown response", [](Json& j) { j["materials"]["hard"]["response"] = "spring"; },
       "/materials/hard/response", "expected one of 'proxy', 'penalty'"},
      {"unknown deformation key",
       [](Json& j) { j["materials"]["soft"]["deformation"]["radius_m"] = 0.01; },
       "/materials/soft/deformation/radius_m", "unknown key 'radius_m'"},
      {"zero elasticity",
       [](Json& j) { j["materials"]["soft"]["deformation"]["elasticity_factor"] = 0; },
       "/materials/soft/deformation/elasticity_factor", "expected a number > 0"},
      {"key with a slash is escaped",
       [](Json& j) {
         j["materials"]["a/b~c"] = {{"bogus", 1}};
       },
       "/materials/a~1b~0c/bogus", "unknown key 'bogus'"},
      {"negative passivity factor",
       [](Json& j) {
         j["world"] = {{"passivity_damping_factor", -1}};
       },
       "/world/passivity_damping_factor", "expected a number >= 0"},
      {"unknown world key",
       [](Json& j) {
         j["world"] = {{"gravity", 9.81}};
       },
       "/world/gravity", "unknown key 'gravity'"},
      {"no bodies", [](Json& j) { j["bodies"] = Json::array(); }, "/bodies", "at least one body"},
      {"body not an object", [](Json& j) { j["bodies"][1] = "ball"; }, "/bodies/1",
       "expected a body (a JSON object), got a string"},
      {"body without a name", [](Json& j) { j["bodies"][1].erase("name"); }, "/bodies/1",
       "missing required key 'name'"},
      {"duplicate body names", [](Json& j) { j["bodies"][1]["name"] = "block"; }, "/bodies/1/name",
       "'block' is used twice"},
      {"unknown body type", [](Json& j) { j["bodies"][1]["type"] = "soft"; }, "/bodies/1/type",
       "expected one of 'static', 'deformable', 'dynamic'"},
      {"unknown contact method", [](Json& j) { j["bodies"][0]["contact_method"] = "fast"; },
       "/bodies/0/contact_method", "expected one of 'exact', 'spheretree', 'knee'"},
      {"position with two numbers",
       [](Json& j) {
         j["bodies"][1]["pose"]["position_m"] = {0.1, 0};
       },
       "/bodies/1/pose/position_m", "expected [x, y, z]"},
      {"position with text",
       [](Json& j) {
         j["bodies"][1]["pose"]["position_m"] = {0.1, "0", 0};
       },
       "/bodies/1/pose/position_m/1", "expected a number in m, got a string"},
      {"both rotation kinds",
       [](Json& j) {
         j["bodies"][1]["pose"]["rotation_deg"] = {0, 0, 90};
         j["bodies"][1]["pose"]["quaternion_wxyz"] = {1, 0, 0, 0};
       },
       "/bodies/1/pose", "not both"},
      {"non-unit quaternion",
       [](Json& j) {
         j["bodies"][1]["pose"]["quaternion_wxyz"] = {1, 1, 0, 0};
       },
       "/bodies/1/pose/quaternion_wxyz", "expected a unit quaternion"},
      {"quaternion with three numbers",
       [](Json& j) {
         j["bodies"][1]["pose"]["quaternion_wxyz"] = {1, 0, 0};
       },
       "/bodies/1/pose/quaternion_wxyz", "expected [w, x, y, z]"},
      {"missing geometry", [](Json& j) { j["bodies"][0].erase("geometry"); }, "/bodies/0",
       "missing required key 'geometry'"},
      {"no geometry kind", [](Json& j) { j["bodies"][0]["geometry"] = Json::object(); },
       "/bodies/0/geometry", "expected one geometry kind"},
      {"two geometry kinds",
       [](Json& j) {
         j["bodies"][0]["geometry"]["sphere"] = {{"radius_m", 0.01}};
       },
       "/bodies/0/geometry", "exactly one geometry kind"},
      {"stray geometry key", [](Json& j) { j["bodies"][0]["geometry"]["scale"] = 2; },
       "/bodies/0/geometry/scale", "unknown key 'scale'"},
      {"flat box",
       [](Json& j) {
         j["bodies"][0]["geometry"]["box"]["half_extents_m"] = {0.02, 0.0, 0.02};
       },
       "/bodies/0/geometry/box/half_extents_m", "expected half extents > 0 m"},
      {"box without extents", [](Json& j) { j["bodies"][0]["geometry"]["box"] = Json::object(); },
       "/bodies/0/geometry/box", "missing required key 'half_extents_m'"},
      {"sphere without radius",
       [](Json& j) { j["bodies"][1]["geometry"]["sphere"].erase("radius_m"); },
       "/bodies/1/geometry/sphere", "missing required key 'radius_m'"},
      {"sphere with too few segments",
       [](Json& j) { j["bodies"][1]["geometry"]["sphere"]["segments"] = 3; },
       "/bodies/1/geometry/sphere/segments", "expected a number >= 8"},
      {"sheet without size",
       [](Json& j) {
         j["bodies"][0]["geometry"] = {{"sheet", {{"nodes_per_side", 16}}}};
       },
       "/bodies/0/geometry/sheet", "missing required key 'size_m'"},
      {"unknown procedural",
       [](Json& j) {
         j["bodies"][0]["geometry"] = {{"procedural", "hip"}};
       },
       "/bodies/0/geometry/procedural", "expected one of 'knee'"},
      {"procedural resolution out of range",
       [](Json& j) {
         j["bodies"][0]["geometry"] = {{"procedural", "knee"}, {"resolution_scale", 10}};
       },
       "/bodies/0/geometry/resolution_scale", "<= 4"},
      {"include_skin as text",
       [](Json& j) {
         j["bodies"][0]["geometry"] = {{"procedural", "knee"}, {"include_skin", "yes"}};
       },
       "/bodies/0/geometry/include_skin", "expected true or false"},
      {"missing materials on a body", [](Json& j) { j["bodies"][0].erase("materials"); },
       "/bodies/0", "missing required key 'materials'"},
      {"unknown material", [](Json& j) { j["bodies"][0]["materials"] = "bone"; },
       "/bodies/0/materials", "expected the name of a material in /materials (hard, soft)"},
      {"material as a number", [](Json& j) { j["bodies"][0]["materials"] = 3; },
       "/bodies/0/materials", "expected a material name or material rules"},
      {"segment without a material",
       [](Json& j) {
         j["bodies"][0]["materials"] = {{"by_tissue", {{"bone", "hard"}}}};
       },
       "/bodies/0/materials", "segment 'block' gets no material"},
      {"unknown tissue",
       [](Json& j) {
         j["bodies"][0]["materials"] = {{"by_tissue", {{"fat", "soft"}}}};
       },
       "/bodies/0/materials/by_tissue/fat", "unknown tissue 'fat'"},
      {"unknown segment",
       [](Json& j) {
         j["bodies"][0]["materials"] = {{"segments", {{"cube", "soft"}}}};
       },
       "/bodies/0/materials/segments/cube", "a segment of body 'block', got 'cube'"},
      {"unknown material in a name rule",
       [](Json& j) {
         j["bodies"][0]["materials"] = {
             {"by_name", {{{"contains", "blo"}, {"material", "steel"}}}}};
       },
       "/bodies/0/materials/by_name/0/material", "got 'steel'"},
      {"name rule without text",
       [](Json& j) {
         j["bodies"][0]["materials"] = {{"by_name", {{{"material", "hard"}}}}};
       },
       "/bodies/0/materials/by_name/0", "missing required key 'contains'"},
      {"missing tools", [](Json& j) { j.erase("tools"); }, "/", "missing required key 'tools'"},
      {"no tools", [](Json& j) { j["tools"] = Json::array(); }, "/tools", "at least one tool"},
      {"duplicate tool names",
       [](Json& j) {
         j["tools"].push_back({{"name", "tip"}});
       },
       "/tools/1/name", "'tip' is used twice"},
      {"huge tool", [](Json& j) { j["tools"][0]["radius_m"] = 0.5; }, "/tools/0/radius_m",
       "<= 0.1"},
      {"finger out of range", [](Json& j) { j["tools"][0]["finger"] = 7; }, "/tools/0/finger",
       "finger index 0..4, got 7"},
      {"fractional finger", [](Json& j) { j["tools"][0]["finger"] = 1.5; }, "/tools/0/finger",
       "finger index"},
      {"finger the device lacks", [](Json& j) { j["tools"][0]["finger"] = 2; }, "/device/profile",
       "tool 'tip' uses finger 2"},
      {"finger used twice",
       [](Json& j) {
         j["device"]["profile"] = "simulated";
         j["tools"][0]["finger"] = 1;
         j["tools"].push_back({{"name", "tip2"}, {"finger", 1}});
       },
       "/tools/1/finger", "finger 1 is used twice"},
      {"one tool without a device host",
       [](Json& j) {
         j["tools"][0]["device_host"] = "trainee";
         j["tools"].push_back({{"name", "probe"}});
       },
       "/tools/1", "names no device_host, while others do"},
      {"device host name with a space",
       [](Json& j) { j["tools"][0]["device_host"] = "the trainee"; }, "/tools/0/device_host",
       "letters, digits"},
      {"five device hosts",
       [](Json& j) {
         j["tools"][0]["device_host"] = "u0";
         for (int k = 1; k < 5; ++k) {
           j["tools"].push_back(
               {{"name", "t" + std::to_string(k)}, {"device_host", "u" + std::to_string(k)}});
         }
       },
       "/tools/4/device_host", "at most 4 device hosts"},
      {"missing device", [](Json& j) { j.erase("device"); }, "/", "missing required key 'device'"},
      {"unknown profile", [](Json& j) { j["device"]["profile"] = "phantom"; }, "/device/profile",
       "expected one of"},
      {"unknown device type", [](Json& j) { j["device"]["type"] = "usb"; }, "/device/type",
       "expected one of 'simulated'"},
      {"neither trajectory nor palpation", [](Json& j) { j["device"].erase("palpation"); },
       "/device", "exactly one of 'trajectory'"},
      {"both trajectory and palpation", [](Json& j) { j["device"]["trajectory"] = "t.csv"; },
       "/device", "exactly one of 'trajectory'"},
      {"missing trajectory file",
       [](Json& j) {
         j["device"].erase("palpation");
         j["device"]["trajectory"] = "nowhere.csv";
       },
       "/device/trajectory", "no such file"},
      {"no targets", [](Json& j) { j["device"]["palpation"]["targets"] = Json::array(); },
       "/device/palpation/targets", "at least one target"},
      {"target on an unknown body",
       [](Json& j) { j["device"]["palpation"]["targets"][0]["body"] = "femur"; },
       "/device/palpation/targets/0/body", "got 'femur'"},
      {"target on an unknown segment",
       [](Json& j) { j["device"]["palpation"]["targets"][0]["segment"] = "patella"; },
       "/device/palpation/targets/0/segment", "expected a segment of body 'block' (block)"},
      {"target without a direction",
       [](Json& j) {
         j["device"]["palpation"]["targets"][0]["from"] = {0, 0, 0};
       },
       "/device/palpation/targets/0/from", "non-zero direction"},
      {"target pressed too deep",
       [](Json& j) { j["device"]["palpation"]["targets"][0]["depth_m"] = 0.5; },
       "/device/palpation/targets/0/depth_m", "<= 0.1"},
      {"zero axis",
       [](Json& j) {
         j["device"]["palpation"]["around_axis"] = {0, 0, 0};
       },
       "/device/palpation/around_axis", "non-zero direction"},
      {"zero move time", [](Json& j) { j["device"]["palpation"]["move_s"] = 0; },
       "/device/palpation/move_s", "expected a number > 0"},
      {"unknown palpation key", [](Json& j) { j["device"]["palpation"]["speed"] = 1; },
       "/device/palpation/speed", "unknown key 'speed'"},
      {"zero time step",
       [](Json& j) {
         j["run"] = {{"dt_s", 0}};
       },
       "/run/dt_s", "expected a number > 0"},
      {"time step too long",
       [](Json& j) {
         j["run"] = {{"dt_s", 0.02}};
       },
       "/run/dt_s", "<= 0.01"},
      {"negative duration",
       [](Json& j) {
         j["run"] = {{"duration_s", -1}};
       },
       "/run/duration_s", ">= 0"},
      {"unknown run key",
       [](Json& j) {
         j["run"] = {{"steps", 100}};
       },
       "/run/steps", "unknown key 'steps'"},
  };
  for (const Mutation& c : cases) {
    SCOPED_TRACE(c.name);
    Json scene = base();
    c.change(scene);
    expect_error(scene, c.where, c.fragment);
  }
}

TEST_F(SceneFileTest, BrokenJsonNamesLineAndColumn) {
  expect_text_error("{\n  \"format\": \"hapsim-scene/1\",\n  \"materials\": }\n", "3:16",
                    "invalid JSON");
  expect_text_error("{ \"format\": \"hapsim-scene/1\", ", "1:31", "invalid JSON");
  expect_text_error("", "1:1", "invalid JSON");
  expect_text_error("[1, 2]", "/", "expected a scene (a JSON object), got an array");
}

TEST_F(SceneFileTest, MissingOrUnreadableFileIsNamed) {
  for (const fs::path& p : {dir_ / "absent.json", dir_}) {
    try {
      (void)load_scene(p);
      ADD_FAILURE() << "loaded " << p;
    } catch (const Error& e) {
      EXPECT_EQ(e.where(), p.string());
      EXPECT_NE(e.detail().find("cannot open"), std::string::npos) << e.detail();
    }
  }
}

TEST_F(SceneFileTest, BadMeshFilesAreNamedWithTheirJsonPath) {
  write("nan.obj", "v 0 0 0\nv 1 0 0\nv 0 nan 0\nf 1 2 3\n");
  write("empty.obj", "# nothing\n");
  write("not_a_folder.txt", "x");
  write("meshes/readme.txt", "no meshes here");
  struct Case {
    Json geometry;
    const char* where;
    const char* fragment;
  };
  const Case cases[] = {
      {{{"mesh", {{"file", "absent.stl"}}}}, "/bodies/0/geometry/mesh/file", "cannot load mesh"},
      {{{"mesh", {{"file", "nan.obj"}}}}, "/bodies/0/geometry/mesh/file", "non_finite_vertices=1"},
      {{{"mesh", {{"file", "empty.obj"}}}}, "/bodies/0/geometry/mesh/file", "cannot read mesh"},
      {{{"mesh", {{"file", "nan.obj"}, {"scale", 0}}}},
       "/bodies/0/geometry/mesh/scale",
       "expected a number > 0"},
      {{{"mesh", {{"file", ""}}}}, "/bodies/0/geometry/mesh/file", "empty string"},
      {{{"mesh", {{"path", "nan.obj"}}}}, "/bodies/0/geometry/mesh/path", "unknown key 'path'"},
      {{{"mesh_folder", {{"folder", "not_a_folder.txt"}}}},
       "/bodies/0/geometry/mesh_folder/folder",
       "is not a folder"},
      {{{"mesh_folder", {{"folder", "meshes"}}}},
       "/bodies/0/geometry/mesh_folder/folder",
       "no file matching '*.stl'"},
      {{{"mesh_folder", {{"folder", "meshes"}, {"pattern", "stl"}}}},
       "/bodies/0/geometry/mesh_folder/pattern",
       "expected a file-name beginning, one '*' and an ending"},
      {{{"mesh_folder", {{"folder", "meshes"}, {"pattern", "*_*.stl"}}}},
       "/bodies/0/geometry/mesh_folder/pattern",
       "one '*'"},
      {{{"mesh_folder", {{"folder", "meshes"}, {"pattern", "Bone_*.stl"}}}},
       "/bodies/0/geometry/mesh_folder/folder",
       "no file matching 'Bone_*.stl'"},
  };
  for (const Case& c : cases) {
    SCOPED_TRACE(c.geometry.dump());
    Json scene = base();
    scene["bodies"][0]["geometry"] = c.geometry;
    expect_error(scene, c.where, c.fragment);
  }
}

TEST_F(SceneFileTest, DataPathsNeedTheDataFolder) {
  Json scene = base();
  scene["bodies"][0]["geometry"] = {{"mesh", {{"file", "data:tet.obj"}}}};
  SceneLoadOptions missing;
  missing.data_dir = dir_ / "no_such_data";
  expect_error(scene, "/bodies/0/geometry/mesh/file", "no_such_data does not exist", missing);
}

// A tetrahedron with 10 mm legs, in millimetres.
const char* kTetObjMm =
    "v 0 0 0\nv 10 0 0\nv 0 10 0\nv 0 0 10\nf 1 3 2\nf 1 2 4\nf 1 4 3\nf 2 3 4\n";

TEST_F(SceneFileTest, MeshesInMillimetresResolveRelativeAndDataPaths) {
  write("scenes/meshes/tet.obj", kTetObjMm);
  write("data/parts/tet.obj", kTetObjMm);
  Json scene = base();
  scene["bodies"][0]["geometry"] = {{"mesh", {{"file", "meshes/tet.obj"}, {"scale", 0.001}}}};
  scene["bodies"][1]["geometry"] = {{"mesh", {{"file", "data:parts/tet.obj"}, {"scale", 0.001}}}};
  SceneLoadOptions options;
  options.data_dir = dir_ / "data";
  const SceneDescription s = load_scene(write("scenes/scene.json", scene.dump()), options);
  for (const BodyDescription& b : s.world.bodies) {
    ASSERT_EQ(b.segments.size(), 1u);
    const TriangleMesh& m = b.segments[0].mesh;
    EXPECT_EQ(m.vertex_count(), 4u);
    EXPECT_EQ(m.triangle_count(), 4u);
    EXPECT_NEAR(m.bounds().max().x(), 0.010, 1e-12);
    EXPECT_NEAR(m.bounds().max().z(), 0.010, 1e-12);
  }
}

TEST_F(SceneFileTest, MeshFolderGivesOneSegmentPerFileWithMaterialPrecedence) {
  // Four parts; names lose the prefix and suffix. Precedence: a segment's own entry, then the
  // first name rule that matches, then its tissue (none here), then the default.
  for (const char* name : {"P_Bone_A_s", "P_Bone_B_s", "P_Muscle_C_s", "P_Other_s"}) {
    write(std::string("parts/") + name + ".obj", kTetObjMm);
  }
  write("parts/ignored.stl.txt", "not matched by the pattern");
  Json scene = base();
  scene["materials"]["bone"] = {{"stiffness_n_per_m", 4000}};
  scene["bodies"][0]["geometry"] = {{"mesh_folder",
                                     {{"folder", "parts"},
                                      {"pattern", "*.OBJ"},  // endings match case-insensitively
                                      {"scale", 0.001},
                                      {"strip_prefix", "P_"},
                                      {"strip_suffix", "_s"}}}};
  scene["bodies"][0]["materials"] = {
      {"default", "soft"},
      {"by_name",
       {{{"contains", "bone_"}, {"material", "bone"}},  // case-insensitive
        {{"contains", "muscle"}, {"material", "hard"}}}},
      {"segments", {{"Bone_B", "hard"}}}};
  scene["device"]["palpation"]["targets"][0]["segment"] = "Bone_A";
  const SceneDescription s = load_scene(write("scene.json", scene.dump()));
  const BodyDescription& body = s.world.bodies[0];
  ASSERT_EQ(body.segments.size(), 4u);
  std::map<std::string, std::string> material_of;
  for (const SegmentDescription& seg : body.segments) {
    material_of[seg.name] = s.world.materials[seg.material].name;
  }
  EXPECT_EQ(material_of.at("Bone_A"), "bone");
  EXPECT_EQ(material_of.at("Bone_B"), "hard");  // its own entry beats the rule
  EXPECT_EQ(material_of.at("Muscle_C"), "hard");
  EXPECT_EQ(material_of.at("Other"), "soft");  // the default
}

TEST_F(SceneFileTest, RotationsAreFixedAxisDegreesOrUnitQuaternions) {
  Json scene = base();
  scene["bodies"][0]["pose"] = {{"rotation_deg", {0, 0, 90}}};
  scene["bodies"][1]["pose"] = {{"position_m", {0.1, 0, 0}},
                                {"quaternion_wxyz", {std::sqrt(0.5), 0, 0, std::sqrt(0.5)}}};
  const SceneDescription s = load_scene(write("scene.json", scene.dump()));
  for (const BodyDescription& b : s.world.bodies) {
    // 90 degrees about z takes +x to +y.
    EXPECT_TRUE((b.X_world_body.linear() * Vec3::UnitX()).isApprox(Vec3::UnitY(), 1e-12));
  }
  // About fixed x, then y, then z: R = Rz(90) Ry(90) Rx(0); Ry(90) takes +z to +x, then Rz(90)
  // takes +x to +y. (The other order, Ry after Rz, would leave +z at +x.)
  scene["bodies"][0]["pose"] = {{"rotation_deg", {0, 90, 90}}};
  const SceneDescription t = load_scene(write("scene.json", scene.dump()));
  EXPECT_TRUE(
      (t.world.bodies[0].X_world_body.linear() * Vec3::UnitZ()).isApprox(Vec3::UnitY(), 1e-12));
}

TEST_F(SceneFileTest, TrajectoryPathsResolveBesideTheSceneFile) {
  const fs::path traj = write("scenes/paths/t.csv", "t,x,y,z,qw,qx,qy,qz\n0,0,0,0.1,1,0,0,0\n");
  Json scene = base();
  scene["device"].erase("palpation");
  scene["device"]["trajectory"] = "paths/t.csv";
  const SceneDescription s = load_scene(write("scenes/scene.json", scene.dump()));
  EXPECT_TRUE(fs::equivalent(s.device.trajectory_file, traj));
  EXPECT_FALSE(s.device.has_palpation);
}

TEST_F(SceneFileTest, TeleopScenesNameTheirMistakes) {
  const Json teleop = Json::parse(R"({
    "format": "hapsim-scene/1",
    "teleop": { "slave": { "model": "procedural" }, "ball": { "start_m": [0.5, -0.25, 0.03] } },
    "device": { "pick_and_place": { "place_m": [0.5, 0.25, 0.08] } }
  })");
  const Mutation cases[] = {
      {"bodies in a teleop scene", [](Json& j) { j["bodies"] = Json::array(); }, "/bodies",
       "unknown key 'bodies'"},
      {"unknown slave model", [](Json& j) { j["teleop"]["slave"]["model"] = "kuka"; },
       "/teleop/slave/model", "expected one of 'procedural'"},
      {"missing URDF",
       [](Json& j) {
         j["teleop"]["slave"] = {{"urdf", "nowhere.urdf"}};
       },
       "/teleop/slave/urdf", "no such file"},
      {"neither slave kind", [](Json& j) { j["teleop"]["slave"] = Json::object(); },
       "/teleop/slave", "expected one of 'model'"},
      {"zero scale",
       [](Json& j) {
         j["teleop"]["mapping"] = {{"scale", 0}};
       },
       "/teleop/mapping/scale", "expected a number > 0"},
      {"heavy ball", [](Json& j) { j["teleop"]["ball"]["mass_kg"] = 500; }, "/teleop/ball/mass_kg",
       "<= 100"},
      {"no script", [](Json& j) { j["device"].erase("pick_and_place"); }, "/device",
       "exactly one of 'trajectory'"},
      {"script without a place", [](Json& j) { j["device"]["pick_and_place"].erase("place_m"); },
       "/device/pick_and_place", "missing required key 'place_m'"},
      {"two scripts", [](Json& j) { j["device"]["palpation"] = 1; }, "/device",
       "exactly one of 'trajectory'"},
      {"a glove for the master", [](Json& j) { j["device"]["type"] = "glove"; }, "/device/type",
       "a rig's device is its master arm"},
  };
  for (const Mutation& c : cases) {
    SCOPED_TRACE(c.name);
    Json scene = teleop;
    c.change(scene);
    expect_error(scene, c.where, c.fragment);
  }
  // Read as a rig scene: the ball, the sheet and the floor are bodies the rig names; one note.
  const SceneDescription s = load_scene(write("teleop.json", teleop.dump()));
  EXPECT_TRUE(s.has_rig);
  EXPECT_TRUE(s.teleop.slave_urdf.empty());
  EXPECT_TRUE(s.device.has_pick_and_place);
  EXPECT_TRUE(s.device.pick_and_place.place_m.isApprox(Vec3(0.5, 0.25, 0.08)));
  EXPECT_EQ(s.teleop.scale, 1.6);  // the default
  ASSERT_EQ(s.world.bodies.size(), 3U);
  EXPECT_EQ(s.teleop.ball_body, "ball");
  EXPECT_EQ(s.teleop.sheet_body, "sheet");
  EXPECT_EQ(s.teleop.floor_body, "floor");
  ASSERT_EQ(s.warnings.size(), 1U);
  EXPECT_NE(s.warnings.front().find("older rig dialect, converted on read"), std::string::npos)
      << s.warnings.front();
}

// An older "teleop" file is the same world as the scene written in the one language: the first
// paper's scenes/teleop.json as it was before the "rig" key, converted on read, builds a world
// with the same content hash as today's scenes/teleop.json.
TEST_F(SceneFileTest, AnOlderTeleopFileIsTheSameWorldAsItsRigScene) {
  std::ifstream in(fs::path(HAPSIM_SOURCE_DIR) / "tests" / "data" / "teleop_older_dialect.json");
  const Json old = Json::parse(in);
  const SceneDescription converted = load_scene(write("teleop.json", old.dump()));
  const SceneDescription written =
      load_scene(fs::path(HAPSIM_SOURCE_DIR) / "scenes" / "teleop.json");
  EXPECT_TRUE(written.warnings.empty());
  const World a(make_rig_setup(converted, std::nullopt, false).description);
  const World b(make_rig_setup(written, std::nullopt, false).description);
  EXPECT_EQ(a.content_hash(), b.content_hash());
  EXPECT_EQ(a.description().bodies.size(), b.description().bodies.size());
}

// A "rig" beside the bodies and tools: it names what it drives and reads, and each name must be
// one of the scene's of the right kind.
TEST_F(SceneFileTest, RigScenesNameTheirMistakes) {
  Json rig = base();
  rig["rig"] = Json::parse(R"({ "slave": { "model": "procedural" }, "carries_tool": "tip" })");
  rig["device"].erase("profile");  // a rig's device is its master arm
  const Mutation cases[] = {
      {"unknown key", [](Json& j) { j["rig"]["ball_m"] = 1; }, "/rig/ball_m",
       "unknown key 'ball_m'"},
      {"no such tool", [](Json& j) { j["rig"]["carries_tool"] = "probe"; }, "/rig/carries_tool",
       "no tool named 'probe'"},
      {"no such body", [](Json& j) { j["rig"]["ball"] = "marble"; }, "/rig/ball",
       "no body named 'marble'"},
      {"a ball that is not dynamic", [](Json& j) { j["rig"]["ball"] = "block"; }, "/rig/ball",
       "must be dynamic"},
      {"a floor that is not static", [](Json& j) { j["rig"]["floor"] = "ball"; }, "/rig/floor",
       "must be static"},
      {"zero scale",
       [](Json& j) {
         j["rig"]["mapping"] = {{"scale", 0}};
       },
       "/rig/mapping/scale", "expected a number > 0"},
      {"a ball that is not a sphere",
       [](Json& j) {
         j["bodies"].push_back(Json::parse(R"({ "name": "cube", "type": "dynamic", "mass_kg": 0.1,
             "geometry": { "box": { "half_extents_m": [0.02, 0.02, 0.02] } },
             "materials": "soft" })"));
         j["rig"]["ball"] = "cube";
       },
       "/rig/ball", "must be a sphere"},
      {"a sheet that is not a sheet", [](Json& j) { j["rig"]["sheet"] = "ball"; }, "/rig/sheet",
       "must be a sheet"},
      {"a device profile", [](Json& j) { j["device"]["profile"] = "touch"; }, "/device/profile",
       "a rig's device is its simulated master arm"},
      {"the teleop dialect's ball",
       [](Json& j) {
         j["rig"]["ball"] = {{"mass_kg", 0.1}};
       },
       "/rig/ball", "a body name"},
  };
  for (const Mutation& c : cases) {
    SCOPED_TRACE(c.name);
    Json scene = rig;
    c.change(scene);
    expect_error(scene, c.where, c.fragment);
  }
  const SceneDescription s = load_scene(write("rig.json", rig.dump()));
  EXPECT_TRUE(s.has_rig);
  EXPECT_EQ(s.teleop.carried_tool, "tip");
  EXPECT_TRUE(s.teleop.ball_body.empty());
  EXPECT_EQ(s.world.bodies.size(), 2U);  // the scene's own; the run adds the rig's
}

TEST_F(SceneFileTest, GloveScenesNameTheirMistakes) {
  Json glove = base();
  glove["tools"] = {{{"name", "index"}, {"finger", 1}}, {{"name", "middle"}, {"finger", 2}}};
  glove["device"] = Json::parse(R"({
    "type": "glove", "profile": "simulated",
    "glove_palpation": { "from": [0, 0, 1],
                         "fingers": [ { "finger": 1, "body": "block", "segment": "block" } ] }
  })");
  const Mutation cases[] = {
      {"palpation for a glove", [](Json& j) { j["device"]["palpation"] = Json::object(); },
       "/device/palpation", "scripted by 'glove_palpation'"},
      {"a tool on no finger", [](Json& j) { j["tools"][1]["finger"] = -1; }, "/tools/1/finger",
       "a glove drives the tools"},
      {"a finger without a tool",
       [](Json& j) { j["device"]["glove_palpation"]["fingers"][0]["finger"] = 3; },
       "/device/glove_palpation/fingers/0/finger", "no tool in /tools sits on finger 3"},
      {"a finger twice",
       [](Json& j) {
         j["device"]["glove_palpation"]["fingers"].push_back(
             j["device"]["glove_palpation"]["fingers"][0]);
       },
       "/device/glove_palpation/fingers/1/finger", "listed twice"},
      {"an unknown segment",
       [](Json& j) { j["device"]["glove_palpation"]["fingers"][0]["segment"] = "patella"; },
       "/device/glove_palpation/fingers/0/segment", "got 'patella'"},
      {"neither a segment nor a point",
       [](Json& j) { j["device"]["glove_palpation"]["fingers"][0].erase("segment"); },
       "/device/glove_palpation/fingers/0", "segment"},
      {"a point that is no vector",
       [](Json& j) {
         j["device"]["glove_palpation"]["fingers"][0].erase("segment");
         j["device"]["glove_palpation"]["fingers"][0]["toward_m"] = {0, 1};
       },
       "/device/glove_palpation/fingers/0/toward_m", ""},
      {"no direction",
       [](Json& j) {
         j["device"]["glove_palpation"]["from"] = {0, 0, 0};
       },
       "/device/glove_palpation/from", "non-zero direction"},
      {"glove script on a stylus", [](Json& j) { j["device"]["type"] = "simulated"; }, "/device",
       "need \"type\": \"glove\""},
      {"bad coupling",
       [](Json& j) {
         j["device"]["hand"] = {{"dip_per_pip", -1}};
       },
       "/device/hand/dip_per_pip", ">= 0"},
  };
  for (const Mutation& c : cases) {
    SCOPED_TRACE(c.name);
    Json scene = glove;
    c.change(scene);
    expect_error(scene, c.where, c.fragment);
  }
  const SceneDescription s = load_scene(write("glove.json", glove.dump()));
  EXPECT_TRUE(s.world.has_hand);
  EXPECT_TRUE(s.device.has_glove_palpation);
  EXPECT_EQ(s.device.glove_palpation.fingers.at(0).finger, 1);
  EXPECT_FALSE(s.device.glove_palpation.fingers.at(0).toward_world);
  // A finger may aim at a point instead of a segment (a FEM body has none to name).
  Json at_point = glove;
  at_point["device"]["glove_palpation"]["fingers"][0].erase("segment");
  at_point["device"]["glove_palpation"]["fingers"][0]["toward_m"] = {0.01, 0.02, 0.03};
  const SceneDescription p = load_scene(write("glove_point.json", at_point.dump()));
  ASSERT_TRUE(p.device.glove_palpation.fingers.at(0).toward_world);
  EXPECT_TRUE(
      p.device.glove_palpation.fingers.at(0).toward_world->isApprox(Vec3(0.01, 0.02, 0.03)));
  EXPECT_TRUE(p.device.glove_palpation.fingers.at(0).segment.empty());
}

TEST(ShippedScenes, KneeLoadsElevenSegmentsWithTissueMaterials) {
  const SceneDescription s =
      load_scene(fs::path(HAPSIM_SOURCE_DIR) / "scenes" / "knee_procedural.json");
  ASSERT_EQ(s.world.bodies.size(), 1u);
  const BodyDescription& knee = s.world.bodies[0];
  EXPECT_EQ(knee.kind, BodyKind::kDeformable);
  std::map<std::string, std::string> material_of;
  std::size_t vertices = 0;
  for (const SegmentDescription& seg : knee.segments) {
    material_of[seg.name] = s.world.materials[seg.material].name;
    vertices += seg.mesh.vertex_count();
  }
  // The issue's list: femur, tibia, fibula, patella, quadriceps, hamstrings, gastrocnemius,
  // patellar tendon, both collateral ligaments, skin.
  EXPECT_EQ(knee.segments.size(), 11u);
  EXPECT_EQ(material_of.at("femur"), "bone");
  EXPECT_EQ(material_of.at("patella"), "bone");
  EXPECT_EQ(material_of.at("quadriceps"), "muscle");
  EXPECT_EQ(material_of.at("patellar_tendon"), "tendon");
  EXPECT_EQ(material_of.at("medial_collateral_ligament"), "ligament");
  EXPECT_EQ(material_of.at("skin"), "skin");
  EXPECT_GT(vertices, 12000u);  // "about 13.5k vertices like the paper's model"
  EXPECT_LT(vertices, 16000u);
  EXPECT_EQ(s.device.profile, "omega3");
  EXPECT_EQ(s.device.palpation.targets.size(), 5u);
  EXPECT_TRUE(s.device.palpation.has_around_axis);
}

TEST(ShippedScenes, RealKneeLoadsAllPartsWhenTheDataIsPresent) {
  const fs::path data = test::data_path("knee_vhf_left");
  HAPSIM_SKIP_WITHOUT_DATA(fs::is_directory(data / "stl"), "real knee data not found at " << data);
  SceneLoadOptions options;
  options.data_dir = data;
  const SceneDescription s =
      load_scene(fs::path(HAPSIM_SOURCE_DIR) / "scenes" / "knee_vhf.json", options);
  const BodyDescription& knee = s.world.bodies.at(0);
  EXPECT_EQ(knee.segments.size(), 28u);
  std::size_t vertices = 0;
  for (const SegmentDescription& seg : knee.segments) {
    const std::string material = s.world.materials[seg.material].name;
    vertices += seg.mesh.vertex_count();
    // Every part gets the material its name says (Bone_, Cartilage_, Ligament_, Muscle_).
    const std::string tissue = seg.name.substr(0, seg.name.find('_'));
    std::string expected = tissue;
    expected[0] = static_cast<char>(std::tolower(expected[0]));
    EXPECT_EQ(material, expected) << seg.name;
    // Millimetres became metres: a knee part is centimetres across, not metres.
    const Box3 b = seg.mesh.bounds();
    EXPECT_LT(b.sizes().norm(), 0.6) << seg.name;
  }
  EXPECT_GT(vertices, 200000u);
  EXPECT_EQ(s.world.tools.size(), 5u);
}

}  // namespace
}  // namespace hapsim

namespace hapsim {
namespace {

// Named camera views (docs/scene-format.md#views): read as written, bad ones named by pointer.
TEST_F(SceneFileTest, ViewsLoadByNameAndBadOnesAreNamed) {
  Json scene = base();
  scene["views"] = Json::parse(R"({
    "top": {"eye_m": [0, 0, 1], "target_m": [0, 0, 0]},
    "side": {"eye_m": [1, 0, 0.2], "target_m": [0, 0, 0.1], "fov_deg": 30}
  })");
  const SceneDescription d = load_scene(write("views.json", scene.dump(2)));
  ASSERT_EQ(d.views.size(), 2u);
  EXPECT_EQ(d.views[0].name, "side");  // name order
  EXPECT_EQ(d.views[0].eye_m, Vec3(1.0, 0.0, 0.2));
  EXPECT_EQ(d.views[0].target_m, Vec3(0.0, 0.0, 0.1));
  EXPECT_DOUBLE_EQ(d.views[0].fov_deg, 30.0);
  EXPECT_DOUBLE_EQ(d.views[1].fov_deg, 40.0);  // the default
  scene["views"]["top"]["eye_m"] = Json::array({0, 0, 0});
  expect_error(scene, "/views/top/eye_m", "on its target");
  scene["views"]["top"] =
      Json::parse(R"({"eye_m": [0, 0, 1], "target_m": [0, 0, 0], "fov_deg": 0.5})");
  expect_error(scene, "/views/top/fov_deg", "> 1 and <= 170");
  scene["views"]["top"] = Json::parse(R"({"eye_m": [0, 0, 1], "target_m": [0, 0, 0], "up": 1})");
  expect_error(scene, "/views/top/up", "eye_m");  // the allowed keys are listed
  scene["views"] = Json::array();
  expect_error(scene, "/views", "named camera views");
}

}  // namespace
}  // namespace hapsim
