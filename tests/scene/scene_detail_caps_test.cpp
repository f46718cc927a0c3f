// SceneLoadOptions::detail_caps (scene_file.h): a load that caps detail (the scene fuzz targets)
// builds the same kinds of geometry on fewer cells, says each capped value once, and leaves a
// load without caps exactly as it was. References: the generators called directly at the capped
// values (make_procedural_knee, make_uv_sphere, make_sheet), a box's analytic extent, and the
// fuzz seeds, which must still load whole (or the fuzzer would stop reaching the world).
#include "hapsim/geometry/procedural.h"
#include "hapsim/geometry/procedural_knee.h"
#include "hapsim/scene/scene_file.h"

#include "../../fuzz/scene_fuzz_caps.h"

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

namespace hapsim {
namespace {

namespace fs = std::filesystem;
using Json = nlohmann::json;

// One static body "b" of `geometry`; a palpation of its segment `segment`.
Json scene_with(const Json& geometry, const std::string& segment = "b") {
  Json s = Json::parse(R"({
    "format": "hapsim-scene/1",
    "materials": { "hard": { "stiffness_n_per_m": 2000 } },
    "bodies": [ { "name": "b", "type": "static", "materials": { "default": "hard" } } ],
    "tools": [ { "name": "tip", "radius_m": 0.005 } ],
    "device": { "profile": "touch",
                "palpation": { "targets": [ { "body": "b", "segment": "b", "from": [0, 0, 1] } ] } }
  })");
  s["device"]["palpation"]["targets"][0]["segment"] = segment;
  s["bodies"][0]["geometry"] = geometry;
  return s;
}

SceneDescription load(const Json& scene, const SceneDetailCaps& caps) {
  SceneLoadOptions o;
  o.detail_caps = caps;
  return parse_scene(scene.dump(), "/nonexistent/caps.json", o);
}

std::size_t vertex_count(const SceneDescription& s) {
  std::size_t n = 0;
  for (const auto& seg : s.world.bodies.at(0).segments) {
    n += seg.mesh.vertices.size();
  }
  return n;
}

TEST(SceneDetailCaps, ACsgSolidFinerThanTheBudgetIsCoarsenedAndSaidOnce) {
  const Json g = Json::parse(R"({ "csg": { "box": { "half_extents_m": [0.02, 0.02, 0.02] } },
                                   "resolution_m": 0.0015 })");
  const SceneDescription whole = load(scene_with(g), {});
  EXPECT_TRUE(whole.warnings.empty());
  SceneDetailCaps caps;
  caps.csg_grid_nodes = 8000;
  const SceneDescription coarse = load(scene_with(g), caps);
  ASSERT_EQ(coarse.warnings.size(), 1u);
  EXPECT_NE(coarse.warnings[0].find("/bodies/0/geometry: the CSG display mesh is polygonised at"),
            std::string::npos)
      << coarse.warnings[0];
  // By hand: a 40 mm cube needs ceil(0.04 / r) + 1 + 4 nodes a side, at most 20 (20³ = 8000),
  // so r >= 0.04 / 15 = 2.67 mm; coarsened in steps of 1.25 from 1.5 mm: 1.875, 2.34, 2.93 mm.
  EXPECT_NE(coarse.warnings[0].find("polygonised at 0.00293 m, not 0.0015 m: this load allows at "
                                    "most 8000 grid nodes per solid"),
            std::string::npos)
      << coarse.warnings[0];
  // 8000 nodes is 20 a side with 2 cells of padding each way: about 15 cells over 40 mm instead
  // of 27 (the flat faces' vertices, 16k at 1.5 mm, fall to about 4k).
  EXPECT_LT(vertex_count(coarse), vertex_count(whole) / 3);
  // Still the box: its extent within a coarse cell (40 mm / 15) of the analytic 40 mm.
  const TriangleMesh& m = coarse.world.bodies.at(0).segments.at(0).mesh;
  const Box3 b = m.bounds();
  for (int a = 0; a < 3; ++a) {
    EXPECT_NEAR(b.sizes()[a], 0.04, 0.04 / 15.0);
  }
  // The segment still answers contact with the exact solid, whatever the display mesh.
  EXPECT_TRUE(coarse.world.bodies.at(0).segments.at(0).csg.has_value());
}

TEST(SceneDetailCaps, ASolidWithinTheBudgetKeepsItsResolution) {
  const Json g = Json::parse(R"({ "csg": { "box": { "half_extents_m": [0.02, 0.02, 0.02] } },
                                   "resolution_m": 0.01 })");
  SceneDetailCaps caps;
  caps.csg_grid_nodes = 8000;
  const SceneDescription s = load(scene_with(g), caps);
  EXPECT_TRUE(s.warnings.empty());
  EXPECT_EQ(vertex_count(s), vertex_count(load(scene_with(g), {})));
}

TEST(SceneDetailCaps, TheKneeSphereAndSheetTakeTheCappedValues) {
  SceneDetailCaps caps;
  caps.knee_resolution_scale = 0.5;
  caps.sphere_segments = 16;
  caps.sheet_nodes_per_side = 8;
  const SceneDescription knee = load(
      scene_with(Json::parse(R"({ "procedural": "knee", "resolution_scale": 2.0 })"), "patella"),
      caps);
  ProceduralKneeOptions ko;
  ko.resolution_scale = 0.5;
  const std::vector<KneePart> parts = make_procedural_knee(ko);
  const auto& segments = knee.world.bodies.at(0).segments;
  ASSERT_EQ(segments.size(), parts.size());
  for (std::size_t i = 0; i < parts.size(); ++i) {
    EXPECT_EQ(segments[i].name, parts[i].name);
    EXPECT_EQ(segments[i].mesh.vertices.size(), parts[i].mesh.vertices.size()) << parts[i].name;
    EXPECT_GT(parts[i].mesh.triangles.size(), 0u) << parts[i].name;
  }
  ASSERT_EQ(knee.warnings.size(), 1u);
  EXPECT_NE(knee.warnings[0].find("/bodies/0/geometry/resolution_scale: 2 lowered to 0.5"),
            std::string::npos)
      << knee.warnings[0];

  const SceneDescription sphere =
      load(scene_with(Json::parse(R"({ "sphere": { "radius_m": 0.03, "segments": 64 } })")), caps);
  EXPECT_EQ(vertex_count(sphere), make_uv_sphere(0.03, 16, 8).vertices.size());
  ASSERT_EQ(sphere.warnings.size(), 1u);
  EXPECT_NE(sphere.warnings[0].find("segments: 64 lowered to 16"), std::string::npos);

  const SceneDescription sheet = load(
      scene_with(Json::parse(R"({ "sheet": { "size_m": 0.2, "nodes_per_side": 32 } })")), caps);
  EXPECT_EQ(vertex_count(sheet), make_sheet(8, 0.2).vertices.size());
  EXPECT_EQ(sheet.warnings.size(), 1u);

  // Below the caps nothing changes and nothing is said.
  const SceneDescription small =
      load(scene_with(Json::parse(R"({ "sphere": { "radius_m": 0.03, "segments": 12 } })")), caps);
  EXPECT_EQ(vertex_count(small), make_uv_sphere(0.03, 12, 6).vertices.size());
  EXPECT_TRUE(small.warnings.empty());
}

// The fuzz targets' caps leave every scene seed loading whole: a cap that made the knee or the
// CSG block fail would stop the fuzzer at the loader, far from the world it is meant to reach.
TEST(SceneDetailCaps, TheFuzzSeedsStillLoadUnderTheFuzzCaps) {
  const fs::path corpus = fs::path(HAPSIM_SOURCE_DIR) / "fuzz" / "corpus" / "scene";
  SceneLoadOptions o;
  o.data_dir = "/nonexistent/hapsim-fuzz-data";
  o.detail_caps = fuzz::kSceneDetailCaps;
  for (const char* name :
       {"knee.json", "knee_hand.json", "csg_block.json", "hand_ball_sheet.json", "teleop.json"}) {
    std::ifstream in(corpus / name);
    std::stringstream text;
    text << in.rdbuf();
    SCOPED_TRACE(name);
    const SceneDescription s = parse_scene(text.str(), "/nonexistent/hapsim-fuzz/s.json", o);
    for (const auto& body : s.world.bodies) {
      for (const auto& seg : body.segments) {
        EXPECT_GT(seg.mesh.triangles.size(), 0u) << body.name << "/" << seg.name;
      }
    }
  }
}

}  // namespace
}  // namespace hapsim
