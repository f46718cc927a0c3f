// CSG solids in scene files: a valid scene gives the solid it describes (poses applied, checked
// against analytic distances), a World built from it pushes a probe out of the solid with
// F = k·x along the solid's exact normal, and every kind of bad node is refused with the JSON
// pointer of the offending value (written from docs/scene-format.md, not read from the reader).
#include "hapsim/scene/csg_reader.h"
#include "hapsim/scene/scene_file.h"

#include "hapsim/core/error.h"
#include "hapsim/world/world.h"

#include "support/temp_dir_test.h"

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <unistd.h>
#include <filesystem>
#include <fstream>
#include <functional>
#include <string>

namespace hapsim {
namespace {

namespace fs = std::filesystem;
using Json = nlohmann::json;

// A cylinder (radius 30 mm, half height 20 mm) with a spherical dimple of radius 15 mm cut into
// its top, placed at x = 0.1 m and turned 90° about x, so the body's +z (the dimple's opening)
// is the world's -y. Penalty material k = 800 N/m, no damping floor (the probes are static).
Json dimple_scene() {
  return Json::parse(R"({
    "format": "hapsim-scene/1",
    "world": { "passivity_damping_factor": 0 },
    "materials": { "gel": { "response": "penalty", "stiffness_n_per_m": 800,
                            "max_penetration_m": 0.02, "max_force_n": 100 } },
    "bodies": [
      { "name": "dimple", "pose": { "position_m": [0.1, 0, 0], "rotation_deg": [90, 0, 0] },
        "geometry": {
          "csg": { "difference": [
            { "cylinder": { "radius_m": 0.03, "half_height_m": 0.02 } },
            { "sphere": { "radius_m": 0.015 }, "pose": { "position_m": [0, 0, 0.02] } } ] },
          "resolution_m": 0.002 },
        "materials": "gel" }
    ],
    "tools": [ { "name": "tip", "radius_m": 0.002 } ],
    "device": { "profile": "touch",
                "palpation": { "targets": [ { "body": "dimple", "segment": "dimple",
                                              "from": [0, -1, 0] } ] } }
  })");
}

class CsgSceneTest : public test::TempDirTest {
 protected:
  fs::path write(const Json& scene) const {
    return TempDirTest::write("scene.json", scene.dump(2));
  }
};

DeviceInput at(const Vec3& p) {
  DeviceInput in;
  in.p_world = p;
  return in;
}

TEST_F(CsgSceneTest, ADimpledCylinderLoadsAsDescribed) {
  const SceneDescription s = load_scene(write(dimple_scene()));
  ASSERT_EQ(s.world.bodies.size(), 1u);
  const BodyDescription& body = s.world.bodies[0];
  ASSERT_EQ(body.segments.size(), 1u);
  const SegmentDescription& seg = body.segments[0];
  EXPECT_EQ(seg.name, "dimple");
  ASSERT_TRUE(seg.csg.has_value());
  // Analytic distances in the body frame: the dimple's bottom is at z = 5 mm.
  EXPECT_NEAR(seg.csg->distance(Vec3(0, 0, 0)), -0.005, 1e-12);
  EXPECT_NEAR(seg.csg->distance(Vec3(0, 0, -0.015)), -0.005, 1e-12);  // 5 mm above the bottom cap
  EXPECT_NEAR(seg.csg->distance(Vec3(0.04, 0, 0)), 0.01, 1e-12);
  EXPECT_GT(seg.csg->distance(Vec3(0, 0, 0.015)), 0.0);  // in the dimple
  // The display mesh covers the solid: its bounds are the cylinder's, to within a cell.
  ASSERT_FALSE(seg.mesh.triangles.empty());
  const Box3 b = seg.mesh.bounds();
  EXPECT_NEAR(b.min().x(), -0.03, 0.002);
  EXPECT_NEAR(b.max().z(), 0.02, 0.002);
  EXPECT_NEAR(b.min().z(), -0.02, 0.002);
}

TEST_F(CsgSceneTest, APressedProbeFeelsHookeAlongTheExactNormal) {
  const SceneDescription s = load_scene(write(dimple_scene()));
  World world(s.world);
  EXPECT_EQ(world.rest_query(0, 0).method_name(), "csg");
  const Iso3 X_world_body = s.world.bodies[0].X_world_body;
  const Vec3 n_world = X_world_body.linear() * Vec3::UnitZ();  // the dimple's bottom normal
  EXPECT_LT((n_world - Vec3(0, -1, 0)).norm(), 1e-12);
  struct Press {
    const char* what;
    double z_body;  // the probe centre on the axis, body frame
    double depth_m;
  };
  // Bottom of the dimple at z = 5 mm; tool radius 2 mm. 3 mm into the solid (exact field) and
  // 1.5 mm above the bottom, in the dimple (a bound the query certifies).
  for (const Press& p : {Press{"inside", 0.002, 0.005}, Press{"in the dimple", 0.0065, 0.0005}}) {
    SCOPED_TRACE(p.what);
    World w(s.world);
    const StepResult& r = w.step(at(X_world_body * Vec3(0, 0, p.z_body)), 1e-3);
    ASSERT_EQ(r.contacts.size(), 1u);
    EXPECT_NEAR(r.contacts[0].depth_m, p.depth_m, 1e-12);
    EXPECT_LT((r.contacts[0].normal_world - n_world).norm(), 1e-12);
    EXPECT_LT((r.contacts[0].point_world - X_world_body * Vec3(0, 0, 0.005)).norm(), 1e-12);
    EXPECT_LT((r.tools[0].force_world_n - 800.0 * p.depth_m * n_world).norm(), 1e-9)
        << r.tools[0].force_world_n.transpose();
  }
  // Clear of the solid: no force.
  const StepResult& free = world.step(at(X_world_body * Vec3(0, 0, 0.03)), 1e-3);
  EXPECT_EQ(free.contacts.size(), 0u);
  EXPECT_EQ(free.tools[0].force_world_n, Vec3::Zero());
}

TEST_F(CsgSceneTest, EveryContactMethodAndADeformableBodyUseTheSolid) {
  for (const char* method : {"exact", "spheretree", "knee"}) {
    SCOPED_TRACE(method);
    Json scene = dimple_scene();
    scene["bodies"][0]["contact_method"] = method;
    scene["bodies"][0]["type"] = "deformable";
    const SceneDescription s = load_scene(write(scene));
    World world(s.world);
    EXPECT_EQ(world.rest_query(0, 0).method_name(), "csg");
    const Iso3 X = s.world.bodies[0].X_world_body;
    const StepResult& r = world.step(at(X * Vec3(0, 0, 0.002)), 1e-3);
    ASSERT_EQ(r.contacts.size(), 1u);
    EXPECT_NEAR(r.contacts[0].depth_m, 0.005, 1e-12);
    EXPECT_GT(world.current_deflection_m(0, 0), 0.0);  // the display mesh dents
  }
}

TEST_F(CsgSceneTest, ListsOfManyChildrenAndEveryPrimitiveLoad) {
  Json scene = dimple_scene();
  scene["bodies"][0]["geometry"] = Json::parse(R"({ "csg": { "union": [
      { "box": { "half_extents_m": [0.01, 0.01, 0.01] } },
      { "sphere": { "radius_m": 0.01 }, "pose": { "position_m": [0.02, 0, 0] } },
      { "cylinder": { "radius_m": 0.005, "half_height_m": 0.01 },
        "pose": { "position_m": [0, 0.02, 0] } },
      { "cone": { "radius_m": 0.01, "height_m": 0.02 }, "pose": { "position_m": [0, 0, 0.01] } },
      { "intersection": [
          { "torus": { "major_radius_m": 0.01, "minor_radius_m": 0.004 } },
          { "box": { "half_extents_m": [0.02, 0.02, 0.02] } } ],
        "pose": { "position_m": [-0.03, 0, 0], "quaternion_wxyz": [1, 0, 0, 0] } } ] } })");
  scene["device"]["palpation"]["targets"][0]["from"] = {0, 0, 1};
  const SceneDescription s = load_scene(write(scene));
  const CsgSolid& solid = *s.world.bodies[0].segments[0].csg;
  EXPECT_NEAR(solid.distance(Vec3(0, 0, 0.03)), 0.0, 1e-12);         // the cone's apex
  EXPECT_NEAR(solid.distance(Vec3(0.035, 0, 0)), 0.005, 1e-12);      // beyond the sphere
  EXPECT_NEAR(solid.distance(Vec3(-0.044, 0, 0)), 0.0, 1e-12);       // the torus' outer equator
  EXPECT_NEAR(solid.distance(Vec3(0, 0.02, -0.012)), 0.002, 1e-12);  // under the cylinder
}

struct Bad {
  const char* name;
  std::function<void(Json&)> change;
  std::string where;  // JSON pointer
  const char* fragment;
};

TEST_F(CsgSceneTest, EveryBadNodeNamesItsPlace) {
  const auto set_csg = [](const char* text) {
    return [text](Json& j) { j["bodies"][0]["geometry"]["csg"] = Json::parse(text); };
  };
  const auto set_difference_child = [](const char* text) {
    return
        [text](Json& j) { j["bodies"][0]["geometry"]["csg"]["difference"][1] = Json::parse(text); };
  };
  std::string deep = R"({ "sphere": { "radius_m": 0.01 } })";
  for (int i = 0; i < kCsgMaxDepth; ++i) {
    deep = R"({ "union": [ { "sphere": { "radius_m": 0.01 } }, )" + deep + " ] }";
  }
  Json many = Json::array();
  for (std::size_t i = 0; i <= kCsgMaxPrimitives; ++i) {
    many.push_back({{"sphere", {{"radius_m", 0.001}}}});
  }
  const Bad cases[] = {
      {"unknown key in a node", [](Json& j) { j["bodies"][0]["geometry"]["csg"]["colour"] = 1; },
       "/bodies/0/geometry/csg/colour", "unknown key 'colour'"},
      {"unknown solid kind", set_csg(R"({ "pyramid": { "height_m": 1 } })"),
       "/bodies/0/geometry/csg/pyramid", "unknown key 'pyramid'"},
      {"no solid kind", set_csg("{}"), "/bodies/0/geometry/csg", "expected one solid kind"},
      {"two solid kinds",
       set_csg(R"({ "sphere": { "radius_m": 0.01 }, "box": { "half_extents_m": [1, 1, 1] } })"),
       "/bodies/0/geometry/csg", "exactly one solid kind"},
      {"node is not an object", set_csg("[1, 2]"), "/bodies/0/geometry/csg",
       "expected a CSG solid"},
      {"settings are not an object", set_difference_child(R"({ "sphere": 0.01 })"),
       "/bodies/0/geometry/csg/difference/1/sphere", "expected sphere settings (a JSON object)"},
      {"radius as text", set_difference_child(R"({ "sphere": { "radius_m": "1" } })"),
       "/bodies/0/geometry/csg/difference/1/sphere/radius_m", "expected a number"},
      {"zero radius", set_difference_child(R"({ "sphere": { "radius_m": 0 } })"),
       "/bodies/0/geometry/csg/difference/1/sphere/radius_m", "expected a number > 0"},
      {"negative radius", set_difference_child(R"({ "sphere": { "radius_m": -0.01 } })"),
       "/bodies/0/geometry/csg/difference/1/sphere/radius_m", "expected a number > 0"},
      {"missing radius", set_difference_child(R"({ "sphere": {} })"),
       "/bodies/0/geometry/csg/difference/1/sphere", "missing required key 'radius_m'"},
      {"unknown primitive key",
       set_difference_child(R"({ "sphere": { "radius_m": 0.01, "segments": 8 } })"),
       "/bodies/0/geometry/csg/difference/1/sphere/segments", "unknown key 'segments'"},
      {"zero half extent", set_difference_child(R"({ "box": { "half_extents_m": [1, 1, 0] } })"),
       "/bodies/0/geometry/csg/difference/1/box/half_extents_m/2", "expected a half extent > 0"},
      {"two half extents", set_difference_child(R"({ "box": { "half_extents_m": [1, 1] } })"),
       "/bodies/0/geometry/csg/difference/1/box/half_extents_m", "expected [x, y, z]"},
      {"negative half height",
       set_difference_child(R"({ "cylinder": { "radius_m": 0.01, "half_height_m": -1 } })"),
       "/bodies/0/geometry/csg/difference/1/cylinder/half_height_m", "expected a number > 0"},
      {"flat cone", set_difference_child(R"({ "cone": { "radius_m": 0.01, "height_m": 0 } })"),
       "/bodies/0/geometry/csg/difference/1/cone/height_m", "expected a number > 0"},
      {"spindle torus",
       set_difference_child(R"({ "torus": { "major_radius_m": 0.01, "minor_radius_m": 0.02 } })"),
       "/bodies/0/geometry/csg/difference/1/torus/minor_radius_m",
       "minor radius <= the major radius"},
      {"empty list", set_csg(R"({ "union": [] })"), "/bodies/0/geometry/csg/union",
       "expected at least 2 solids, got 0"},
      {"one-child list", set_csg(R"({ "intersection": [ { "sphere": { "radius_m": 0.01 } } ] })"),
       "/bodies/0/geometry/csg/intersection", "expected at least 2 solids, got 1"},
      {"list is an object", set_csg(R"({ "union": { "sphere": { "radius_m": 0.01 } } })"),
       "/bodies/0/geometry/csg/union", "expected a list of CSG solids (a JSON array)"},
      {"child is a number", set_difference_child("3"), "/bodies/0/geometry/csg/difference/1",
       "expected a CSG solid"},
      {"bad pose key",
       set_difference_child(R"({ "sphere": { "radius_m": 0.01 }, "pose": { "scale": 2 } })"),
       "/bodies/0/geometry/csg/difference/1/pose/scale", "unknown key 'scale'"},
      {"both rotations", set_difference_child(R"({ "sphere": { "radius_m": 0.01 },
                                 "pose": { "rotation_deg": [0, 0, 0],
                                           "quaternion_wxyz": [1, 0, 0, 0] } })"),
       "/bodies/0/geometry/csg/difference/1/pose", "not both"},
      {"non-unit quaternion", set_difference_child(R"({ "sphere": { "radius_m": 0.01 },
                                 "pose": { "quaternion_wxyz": [2, 0, 0, 0] } })"),
       "/bodies/0/geometry/csg/difference/1/pose/quaternion_wxyz", "unit quaternion"},
      {"nested too deep", set_csg(deep.c_str()),
       "/bodies/0/geometry/csg" +
           [] {
             std::string p;
             // The union at depth kCsgMaxDepth is the last allowed; its first child is too deep.
             for (int i = 1; i < kCsgMaxDepth; ++i) {
               p += "/union/1";
             }
             return p + "/union/0";
           }(),
       "nest at most"},
      {"too many primitives",
       [many](Json& j) {
         j["bodies"][0]["geometry"]["csg"] = {{"union", many}};
       },
       "/bodies/0/geometry/csg/union/" + std::to_string(kCsgMaxPrimitives) + "/sphere", "at most"},
      {"unknown geometry key beside csg",
       [](Json& j) { j["bodies"][0]["geometry"]["colour"] = "red"; }, "/bodies/0/geometry/colour",
       "unknown key 'colour'"},
      {"csg beside another kind",
       [](Json& j) {
         j["bodies"][0]["geometry"]["sphere"] = {{"radius_m", 0.01}};
       },
       "/bodies/0/geometry", "exactly one geometry kind"},
      {"zero resolution", [](Json& j) { j["bodies"][0]["geometry"]["resolution_m"] = 0; },
       "/bodies/0/geometry/resolution_m", "expected a number >= 0.0001"},
      {"huge solid at a fine resolution",
       [](Json& j) {
         j["bodies"][0]["geometry"]["csg"] = {{"sphere", {{"radius_m", 50}}}};
         j["bodies"][0]["geometry"]["resolution_m"] = 0.001;
       },
       "/bodies/0/geometry/resolution_m", "give a coarser resolution_m"},
      {"huge solid at the default resolution",
       [](Json& j) {
         j["bodies"][0]["geometry"].erase("resolution_m");
         j["bodies"][0]["geometry"]["csg"] = {{"box", {{"half_extents_m", {1, 1, 1}}}}};
       },
       "/bodies/0/geometry", "grid nodes"},
      {"empty solid", set_csg(R"({ "difference": [ { "sphere": { "radius_m": 0.01 } },
                                     { "sphere": { "radius_m": 0.02 } } ] })"),
       "/bodies/0/geometry/csg", "cannot polygonise"},
  };
  for (const Bad& b : cases) {
    SCOPED_TRACE(b.name);
    Json scene = dimple_scene();
    b.change(scene);
    const fs::path file = write(scene);
    try {
      (void)load_scene(file);
      ADD_FAILURE() << "loaded without error";
    } catch (const Error& e) {
      EXPECT_EQ(e.where(), file.string() + ":" + b.where) << e.what();
      EXPECT_NE(e.detail().find(b.fragment), std::string::npos)
          << "message: " << e.detail() << "\nexpected to contain: " << b.fragment;
    }
  }
}

}  // namespace
}  // namespace hapsim
