// FEM bodies in scene files (docs/scene-format.md, "FEM bodies"): scenes/fem_block.json gives
// exactly the body it describes (the tets of its tet_block, the solver settings, the material and
// the attachment), a tet_mesh file's regions get their materials, and every bad FEM scene gives
// one hapsim::Error naming the file and the JSON pointer of the mistake. The expected values,
// pointers and fragments are written from the scene and the document, not read back from the
// loader.
#include "hapsim/scene/scene_file.h"

#include "hapsim/core/error.h"
#include "hapsim/deform/fem_body_description.h"
#include "hapsim/world/fem_coupling.h"
#include "hapsim/world/world.h"

#include "support/temp_dir_test.h"

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <functional>
#include <set>
#include <string>

namespace hapsim {
namespace {

namespace fs = std::filesystem;
using Json = nlohmann::json;

const fs::path kScenes = fs::path(HAPSIM_SOURCE_DIR) / "scenes";

// A small FEM scene: a rigid table, and on it a 80 x 60 x 30 mm block of 4 x 3 x 2 cells held by
// the table, pressed once from above.
Json small_fem_scene() {
  return Json::parse(R"({
    "format": "hapsim-scene/1",
    "materials": {
      "table": { "response": "proxy", "stiffness_n_per_m": 3000 },
      "soft": { "response": "penalty", "stiffness_n_per_m": 3000, "max_penetration_m": 0.02 }
    },
    "bodies": [
      { "name": "table", "pose": { "position_m": [0, 0, -0.01] },
        "geometry": { "box": { "half_extents_m": [0.09, 0.07, 0.01] } }, "materials": "table" },
      { "name": "block", "type": "deformable", "deformation": "fem",
        "pose": { "position_m": [-0.04, -0.03, 0] },
        "geometry": { "tet_block": { "size_m": [0.08, 0.06, 0.03], "cells": [4, 3, 2] } },
        "materials": "soft",
        "fem": { "regions": [ { "region": 0, "youngs_modulus_pa": 20000, "poisson_ratio": 0.45 } ],
                 "fixed": { "attached_to": [ { "body": "table" } ] } } }
    ],
    "tools": [ { "name": "tip", "radius_m": 0.005 } ],
    "device": { "profile": "omega3",
                "palpation": { "targets": [ { "body": "block", "segment": "block",
                                              "from": [0, 0, 1] } ] } }
  })");
}

// Two tetrahedra sharing a face, in two volumes with physical tags 1 and 2 (Gmsh MSH 4.1 ASCII),
// both positively oriented; coordinates in centimetres of a 1-unit corner.
constexpr const char* kTwoRegionMsh = R"($MeshFormat
4.1 0 8
$EndMeshFormat
$Entities
0 0 0 2
1 0 0 0 1 1 1 1 1 0
2 0 0 0 1 1 1 1 2 0
$EndEntities
$Nodes
1 5 1 5
3 1 0 5
1
2
3
4
5
0 0 0
1 0 0
0 1 0
0 0 1
1 1 1
$EndNodes
$Elements
2 2 1 2
3 1 4 1
1 1 2 3 4
3 2 4 1
2 2 3 4 5
$EndElements
)";

// The small scene's block made of the two-region mesh (scale 0.01: 1 cm), held below z = 0.
Json tet_mesh_scene(const fs::path& msh, const Json& regions) {
  Json j = small_fem_scene();
  Json& block = j["bodies"][1];
  block["geometry"] = {{"tet_mesh", {{"file", msh.string()}, {"scale", 0.01}}}};
  block["fem"] = {{"regions", regions}, {"fixed", {{"below_z_m", 0.0}}}};
  return j;
}

class FemSceneTest : public test::TempDirTest {
 protected:
  // Loads `scene` from a file in the test's folder; expects one Error whose where() is
  // "<file>:<pointer>" and whose message holds `fragment`, the text a user sees naming both.
  void expect_error(const Json& scene, const std::string& pointer,
                    const std::string& fragment) const {
    const fs::path file = write("scene.json", scene.dump(2));
    try {
      (void)load_scene(file);
      ADD_FAILURE() << "loaded without error; expected " << pointer << ": " << fragment;
    } catch (const Error& e) {
      EXPECT_EQ(e.where(), file.string() + ":" + pointer) << e.what();
      EXPECT_NE(e.detail().find(fragment), std::string::npos)
          << "message: " << e.detail() << "\nexpected to contain: " << fragment;
      EXPECT_NE(std::string(e.what()).find(file.string() + ":" + pointer), std::string::npos)
          << e.what();
    }
  }
};

TEST_F(FemSceneTest, FemBlockSceneDescribesOneCorotationalBlockAttachedToTheTable) {
  const SceneDescription s = load_scene(kScenes / "fem_block.json");
  ASSERT_EQ(s.world.bodies.size(), 2u);
  std::size_t fem_bodies = 0;
  for (const BodyDescription& b : s.world.bodies) {
    fem_bodies += b.fem ? 1u : 0u;
  }
  EXPECT_EQ(fem_bodies, 1u);

  const BodyDescription& table = s.world.bodies[0];
  EXPECT_EQ(table.name, "table");
  EXPECT_EQ(table.kind, BodyKind::kStatic);
  EXPECT_NE(table.deformation, BodyDeformation::kFem);

  const BodyDescription& block = s.world.bodies[1];
  EXPECT_EQ(block.name, "block");
  EXPECT_EQ(block.kind, BodyKind::kDeformable);
  EXPECT_EQ(block.deformation, BodyDeformation::kFem);
  EXPECT_TRUE(block.X_world_body.translation().isApprox(Vec3(-0.04, -0.03, 0.0)));
  ASSERT_TRUE(block.fem);
  const FemBodyDescription& fem = *block.fem;

  // tet_block 80 x 60 x 30 mm, cells [16, 12, 6]: 6 tets per cube, (n + 1) nodes per axis, the box
  // [0, size] in the body frame.
  EXPECT_EQ(fem.tets.tet_count(), 6u * 16u * 12u * 6u);
  EXPECT_EQ(fem.tets.node_count(), 17u * 13u * 7u);
  const Box3 bounds = fem.tets.bounds();
  EXPECT_TRUE(bounds.min().isApprox(Vec3::Zero()));
  EXPECT_TRUE(bounds.max().isApprox(Vec3(0.08, 0.06, 0.03)));
  EXPECT_NEAR(fem.tets.volume(), 0.08 * 0.06 * 0.03, 1e-12);
  for (std::size_t t = 0; t < fem.tets.tet_count(); ++t) {
    ASSERT_EQ(fem.tets.region(t), 0) << "tet " << t;
  }

  EXPECT_EQ(fem.options.elasticity, FemElasticity::kCorotational);
  EXPECT_EQ(fem.options.integration, FemIntegration::kBackwardEuler);
  EXPECT_EQ(fem.options.dt_s, 0.01);
  EXPECT_EQ(fem.contact_patch_radius_m, 0.009);

  ASSERT_EQ(fem.materials.size(), 1u);
  EXPECT_EQ(fem.materials[0].region, 0);
  const FemMaterial& m = fem.materials[0].material;
  EXPECT_EQ(m.youngs_modulus_pa, 20000.0);
  EXPECT_EQ(m.poisson_ratio, 0.45);
  EXPECT_EQ(m.density_kg_per_m3, 1000.0);
  EXPECT_EQ(m.rayleigh_mass_per_s, 2.0);
  EXPECT_EQ(m.rayleigh_stiffness_s, 0.01);

  // Held by the table alone: every segment of it, nodes within 0.5 mm.
  ASSERT_EQ(fem.attached_to.size(), 1u);
  EXPECT_EQ(fem.attached_to[0].body, "table");
  EXPECT_EQ(fem.attached_to[0].segment, "");
  EXPECT_EQ(fem.attached_to[0].within_m, 0.0005);
  EXPECT_TRUE(fem.fixed_nodes.empty());
  EXPECT_FALSE(fem.fixed_below_z_m.has_value());

  // One segment, named after the body: the tets' boundary (the grid's outer nodes, two triangles
  // per outer cube face), with the block's contact material.
  EXPECT_FALSE(fem.embedded_surface);
  ASSERT_EQ(block.segments.size(), 1u);
  EXPECT_EQ(block.segments[0].name, "block");
  EXPECT_EQ(block.segments[0].mesh.vertex_count(), 17u * 13u * 7u - 15u * 11u * 5u);
  EXPECT_EQ(block.segments[0].mesh.triangles.size(), 4u * (16u * 12u + 16u * 6u + 12u * 6u));
  EXPECT_EQ(s.world.materials[block.segments[0].material].name, "soft_block");
  EXPECT_NE(fem.source.find("fem_block.json"), std::string::npos) << fem.source;
}

TEST_F(FemSceneTest, FemSettingsLeftOutTakeTheDocumentedDefaults) {
  Json j = small_fem_scene();
  j["bodies"][1]["fem"] = {{"fixed", {{"below_z_m", 0.001}}}};
  const SceneDescription s = load_scene(write("scene.json", j.dump()));
  const FemBodyDescription& fem = *s.world.bodies[1].fem;
  EXPECT_EQ(fem.options.elasticity, FemElasticity::kCorotational);
  EXPECT_EQ(fem.options.integration, FemIntegration::kBackwardEuler);
  EXPECT_EQ(fem.options.dt_s, 0.01);
  EXPECT_TRUE(fem.options.gravity_m_per_s2.isZero());
  EXPECT_EQ(fem.options.max_cg_iterations, 200);
  EXPECT_EQ(fem.options.cg_relative_tolerance, 1e-5);
  EXPECT_EQ(fem.contact_patch_radius_m, 0.004);
  EXPECT_EQ(fem.contact_margin_m, 0.01);
  ASSERT_EQ(fem.materials.size(), 1u);  // a tet_block is all region 0
  EXPECT_EQ(fem.materials[0].region, 0);
  EXPECT_EQ(fem.materials[0].material.youngs_modulus_pa, 10000.0);
  EXPECT_EQ(fem.materials[0].material.poisson_ratio, 0.45);
  EXPECT_EQ(fem.materials[0].material.density_kg_per_m3, 1000.0);
  EXPECT_EQ(fem.materials[0].material.rayleigh_mass_per_s, 0.0);
  EXPECT_EQ(fem.materials[0].material.rayleigh_stiffness_s, 0.0);
  ASSERT_TRUE(fem.fixed_below_z_m.has_value());
  EXPECT_EQ(*fem.fixed_below_z_m, 0.001);
}

// A patch smaller than the mesh can carry is raised, and the loader says so once (the block's
// 4 x 3 x 2 cells are 20 x 20 x 15 mm: its boundary's edges average about 22 mm, the patch
// becomes 1.5 times that); a patch the mesh carries is left alone, silently.
TEST_F(FemSceneTest, APatchTooSmallForTheMeshIsRaisedAndSaidOnce) {
  const SceneDescription coarse = load_scene(write("coarse.json", small_fem_scene().dump()));
  std::size_t said = 0;
  for (const std::string& w : coarse.warnings) {
    if (w.find("body 'block': contact patch radius 4.0 mm raised to") != std::string::npos) {
      ++said;
    }
  }
  EXPECT_EQ(said, 1u);
  const TriangleMesh& surface = coarse.world.bodies[1].segments[0].mesh;
  const double raised_m = fem_patch_radius_m(0.004, surface);
  EXPECT_GT(raised_m, 1.5 * 0.020);  // longer than the cells' shortest edge
  EXPECT_LT(raised_m, 1.5 * 0.030);  // shorter than their face diagonals
  Json fine = small_fem_scene();
  fine["bodies"][1]["fem"]["contact_patch_radius_m"] = 0.05;
  const SceneDescription kept = load_scene(write("fine.json", fine.dump()));
  for (const std::string& w : kept.warnings) {
    EXPECT_EQ(w.find("contact patch radius"), std::string::npos) << w;
  }
}

TEST_F(FemSceneTest, TetMeshRegionsGetTheirOwnMaterials) {
  const fs::path msh = write("two_regions.msh", kTwoRegionMsh);
  const Json regions = Json::parse(R"([
    { "region": 2, "name": "stiff", "youngs_modulus_pa": 50000, "poisson_ratio": 0.3 },
    { "region": 1, "name": "soft", "youngs_modulus_pa": 5000, "poisson_ratio": 0.49 } ])");
  const SceneDescription s = load_scene(write("scene.json", tet_mesh_scene(msh, regions).dump()));
  const FemBodyDescription& fem = *s.world.bodies[1].fem;
  ASSERT_EQ(fem.tets.tet_count(), 2u);
  ASSERT_EQ(fem.tets.node_count(), 5u);
  EXPECT_EQ(fem.tets.region(0), 1);
  EXPECT_EQ(fem.tets.region(1), 2);
  EXPECT_TRUE(fem.tets.bounds().max().isApprox(Vec3(0.01, 0.01, 0.01)));  // scale 0.01
  ASSERT_EQ(fem.materials.size(), 2u);
  EXPECT_EQ(fem.materials[0].region, 2);
  EXPECT_EQ(fem.materials[0].material.youngs_modulus_pa, 50000.0);
  EXPECT_EQ(fem.materials[1].region, 1);
  EXPECT_EQ(fem.materials[1].material.poisson_ratio, 0.49);
  EXPECT_EQ(*fem.fixed_below_z_m, 0.0);
  EXPECT_FALSE(fem.embedded_surface);
  // The surface is the two tets' boundary: all five nodes, six faces.
  EXPECT_EQ(s.world.bodies[1].segments[0].mesh.vertex_count(), 5u);
  EXPECT_EQ(s.world.bodies[1].segments[0].mesh.triangles.size(), 6u);
}

struct BadFemScene {
  const char* name;
  std::function<void(Json&)> change;
  const char* pointer;
  const char* fragment;
};

TEST_F(FemSceneTest, BadFemScenesNameTheFileAndThePointer) {
  Json& (*block)(Json&) = [](Json& j) -> Json& { return j["bodies"][1]; };
  const BadFemScene cases[] = {
      {"fem deformation with a box geometry",
       [&](Json& j) {
         block(j)["geometry"] = {{"box", {{"half_extents_m", {0.04, 0.03, 0.015}}}}};
       },
       "/bodies/1/geometry", "a FEM body needs a volume"},
      {"tet_block on a deflection body",
       [&](Json& j) {
         block(j)["deformation"] = "deflection";
         block(j).erase("fem");
       },
       "/bodies/1/deformation", "is a volume for \"deformation\": \"fem\""},
      {"tet_block on a static body",
       [](Json& j) {
         j["bodies"][0]["geometry"] = {
             {"tet_block", {{"size_m", {0.18, 0.14, 0.02}}, {"cells", {2, 2, 1}}}}};
       },
       "/bodies/0/deformation", "is a volume for \"deformation\": \"fem\""},
      {"fem settings on a deflection body",
       [&](Json& j) {
         block(j)["deformation"] = "deflection";
         block(j)["geometry"] = {{"box", {{"half_extents_m", {0.04, 0.03, 0.015}}}}};
       },
       "/bodies/1/fem", "FEM settings need \"deformation\": \"fem\""},
      {"fem deformation on a static body", [&](Json& j) { block(j)["type"] = "static"; },
       "/bodies/1/deformation", "only a \"deformable\" body has a deformation"},
      {"no fixed", [&](Json& j) { block(j)["fem"].erase("fixed"); }, "/bodies/1/fem",
       "a FEM body needs \"fem\": {\"fixed\""},
      {"no fem settings at all", [&](Json& j) { block(j).erase("fem"); }, "/bodies/1",
       "a FEM body needs \"fem\": {\"fixed\""},
      {"a plane below every node",
       [&](Json& j) {
         block(j)["fem"]["fixed"] = {{"below_z_m", -1.0}};
       },
       "/bodies/1/fem/fixed/below_z_m", "no node is that low"},
      {"a material for a region the mesh lacks",
       [&](Json& j) {
         block(j)["fem"]["regions"].push_back({{"region", 7}, {"youngs_modulus_pa", 1000}});
       },
       "/bodies/1/fem/regions/1/region", "the mesh has no region 7"},
      {"a fractional iteration count", [&](Json& j) { block(j)["fem"]["max_cg_iterations"] = 2.5; },
       "/bodies/1/fem/max_cg_iterations", "whole number"},
      {"a region name that is not text",
       [&](Json& j) { block(j)["fem"]["regions"][0]["name"] = 5; }, "/bodies/1/fem/regions/0/name",
       "text"},
      {"attached to a body the scene lacks",
       [&](Json& j) {
         block(j)["fem"]["fixed"] = {{"attached_to", {{{"body", "tabel"}}}}};
       },
       "/bodies/1/fem/fixed/attached_to/0/body", "no body named 'tabel'"},
      {"attached to a segment the body lacks",
       [&](Json& j) {
         block(j)["fem"]["fixed"] = {{"attached_to", {{{"body", "table"}, {"segment", "leg"}}}}};
       },
       "/bodies/1/fem/fixed/attached_to/0/segment", "has no segment 'leg'"},
      {"fixed with nothing in it", [&](Json& j) { block(j)["fem"]["fixed"] = Json::object(); },
       "/bodies/1/fem/fixed", "expected at least one of below_z_m, nodes or attached_to"},
      {"a fixed node out of range",
       [&](Json& j) {
         block(j)["fem"]["fixed"]["nodes"] = {0, 60};  // 5 x 4 x 3 nodes
       },
       "/bodies/1/fem/fixed/nodes/1", "expected a node index in 0..59"},
      {"poisson ratio 0.5", [&](Json& j) { block(j)["fem"]["regions"][0]["poisson_ratio"] = 0.5; },
       "/bodies/1/fem/regions/0/poisson_ratio", "<= 0.499"},
      {"zero Young's modulus",
       [&](Json& j) { block(j)["fem"]["regions"][0]["youngs_modulus_pa"] = 0; },
       "/bodies/1/fem/regions/0/youngs_modulus_pa", "> 0"},
      {"two materials for one region",
       [&](Json& j) {
         block(j)["fem"]["regions"].push_back({{"region", 0}, {"youngs_modulus_pa", 1000}});
       },
       "/bodies/1/fem/regions/1/region", "region 0 has a material already"},
      {"no material for the block's region",
       [&](Json& j) { block(j)["fem"]["regions"][0]["region"] = 1; },
       "/bodies/1/fem/regions/0/region", "the mesh has no region 1"},
      {"unknown elasticity", [&](Json& j) { block(j)["fem"]["elasticity"] = "neo_hookean"; },
       "/bodies/1/fem/elasticity", "'linear', 'corotational'"},
      {"misspelt fem key", [&](Json& j) { block(j)["fem"]["dt"] = 0.01; }, "/bodies/1/fem/dt",
       "unknown key 'dt'"},
      {"zero cells",
       [&](Json& j) {
         block(j)["geometry"]["tet_block"]["cells"] = {0, 3, 2};
       },
       "/bodies/1/geometry/tet_block/cells/0", "expected a whole number of cells in 1..200"},
      {"fractional cells",
       [&](Json& j) {
         block(j)["geometry"]["tet_block"]["cells"] = {4, 2.5, 2};
       },
       "/bodies/1/geometry/tet_block/cells/1", "expected a whole number of cells in 1..200"},
      {"two cell counts",
       [&](Json& j) {
         block(j)["geometry"]["tet_block"]["cells"] = {4, 3};
       },
       "/bodies/1/geometry/tet_block/cells", "expected three cell counts"},
  };
  for (const BadFemScene& c : cases) {
    SCOPED_TRACE(c.name);
    Json scene = small_fem_scene();
    c.change(scene);
    expect_error(scene, c.pointer, c.fragment);
  }
}

TEST_F(FemSceneTest, ATetMeshRegionWithoutAMaterialIsRefused) {
  const fs::path msh = write("two_regions.msh", kTwoRegionMsh);
  const Json only_region_1 =
      Json::parse(R"([ { "region": 1, "youngs_modulus_pa": 5000, "poisson_ratio": 0.45 } ])");
  expect_error(tet_mesh_scene(msh, only_region_1), "/bodies/1/fem/regions",
               "the mesh has region 2 and no material is given for it");
}

// A world built in code gets the same check when it is built: an attachment to a body that is
// not there is named with the place it was given.
TEST_F(FemSceneTest, AttachedToABodyTheWorldLacksIsRefusedWhenTheWorldIsBuilt) {
  const fs::path good = write("good.json", small_fem_scene().dump());
  SceneDescription s = load_scene(good);
  EXPECT_NO_THROW(World world(s.world));
  auto fem = std::make_shared<FemBodyDescription>(*s.world.bodies[1].fem);
  fem->attached_to[0].body = "tabel";
  s.world.bodies[1].fem = fem;
  try {
    World world(std::move(s.world));
    ADD_FAILURE() << "built a world attached to a body that does not exist";
  } catch (const Error& e) {
    EXPECT_EQ(e.where(), good.string() + ":/bodies/1/fem/fixed/attached_to/0/body") << e.what();
    EXPECT_NE(e.detail().find("'tabel'"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace hapsim
