// The procedural knee: every part a closed, manifold, outward mesh; about the paper's 13.5k
// vertices; the skin encloses everything with a few millimetres over the patella; bones do not
// touch; the anatomy sits where the frame says (+z thigh, +y anterior, +x lateral).
#include "hapsim/geometry/procedural_knee.h"

#include "hapsim/collision/mesh_bvh.h"
#include "hapsim/core/error.h"
#include "hapsim/geometry/mesh_validation.h"

#include <gtest/gtest.h>

#include <iostream>
#include <map>
#include <memory>

namespace hapsim {
namespace {

const std::vector<KneePart>& knee() {
  static const std::vector<KneePart> parts = make_procedural_knee();
  return parts;
}

const KneePart& part(const std::string& name) {
  for (const KneePart& p : knee()) {
    if (p.name == name) {
      return p;
    }
  }
  throw std::runtime_error("no part " + name);
}

Vec3 centroid(const TriangleMesh& mesh) {
  Vec3 c = Vec3::Zero();
  for (const Vec3& v : mesh.vertices) {
    c += v;
  }
  return c / static_cast<double>(mesh.vertex_count());
}

TEST(ProceduralKnee, PartsNamesAndTissues) {
  const std::vector<std::pair<std::string, TissueKind>> expected = {
      {"femur", TissueKind::kBone},
      {"tibia", TissueKind::kBone},
      {"fibula", TissueKind::kBone},
      {"patella", TissueKind::kBone},
      {"quadriceps", TissueKind::kMuscle},
      {"hamstrings", TissueKind::kMuscle},
      {"gastrocnemius", TissueKind::kMuscle},
      {"patellar_tendon", TissueKind::kTendon},
      {"medial_collateral_ligament", TissueKind::kLigament},
      {"lateral_collateral_ligament", TissueKind::kLigament},
      {"skin", TissueKind::kSkin},
  };
  ASSERT_EQ(knee().size(), expected.size());
  for (std::size_t i = 0; i < expected.size(); ++i) {
    EXPECT_EQ(knee()[i].name, expected[i].first);
    EXPECT_EQ(knee()[i].tissue, expected[i].second) << expected[i].first;
  }
  EXPECT_EQ(tissue_kind_name(TissueKind::kLigament), "ligament");
}

TEST(ProceduralKnee, EveryPartIsClosedManifoldAndOutward) {
  std::size_t total = 0;
  for (const KneePart& p : knee()) {
    SCOPED_TRACE(p.name);
    const MeshReport r = validate_mesh(p.mesh);
    EXPECT_EQ(r.non_finite_vertices, 0u);
    EXPECT_EQ(r.open_edges, 0u);
    EXPECT_EQ(r.non_manifold_edges, 0u);
    EXPECT_EQ(r.inconsistent_edges, 0u);
    EXPECT_EQ(r.inverted_components, 0u);
    EXPECT_GT(p.mesh.signed_volume(), 0.0);
    std::cout << "  " << p.name << ": " << p.mesh.vertex_count() << " vertices, "
              << p.mesh.signed_volume() * 1e6 << " cm^3\n";
    total += p.mesh.vertex_count();
  }
  std::cout << "  total: " << total << " vertices\n";
  // The paper's model had about 13.5k vertices.
  EXPECT_GT(total, 11000u);
  EXPECT_LT(total, 16500u);
}

TEST(ProceduralKnee, Deterministic) {
  const std::vector<KneePart> again = make_procedural_knee();
  ASSERT_EQ(again.size(), knee().size());
  for (std::size_t i = 0; i < again.size(); ++i) {
    EXPECT_EQ(again[i].mesh.vertices, knee()[i].mesh.vertices) << again[i].name;
    EXPECT_EQ(again[i].mesh.triangles, knee()[i].mesh.triangles) << again[i].name;
  }
}

TEST(ProceduralKnee, SkinEnclosesEverythingThinlyOverThePatella) {
  const MeshBvh skin(part("skin").mesh);
  for (const KneePart& p : knee()) {
    if (p.name == "skin") {
      continue;
    }
    double deepest_gap = kInf;
    for (const Vec3& v : p.mesh.vertices) {
      const double d = skin.closest_point(v).signed_distance;
      ASSERT_LT(d, 0.0) << p.name << " vertex outside the skin";
      deepest_gap = std::min(deepest_gap, -d);
    }
    EXPECT_GT(deepest_gap, 0.002) << p.name << " touches the skin";
  }
  // In front of the patella: the skin is 3-6 mm away along +y.
  const MeshBvh patella(part("patella").mesh);
  const Box3 pb = part("patella").mesh.bounds();
  const Vec3 front(0.0, pb.max().y(), pb.center().z());
  const SurfacePoint on_skin = skin.closest_point(front);
  EXPECT_GE(-on_skin.signed_distance, 0.003);
  EXPECT_LE(-on_skin.signed_distance, 0.0065);
  EXPECT_GT(on_skin.normal.y(), 0.9);  // the nearest skin faces forward
}

TEST(ProceduralKnee, BonesDoNotTouch) {
  const char* bones[] = {"femur", "tibia", "fibula", "patella"};
  for (const char* a : bones) {
    const MeshBvh bvh(part(a).mesh);
    for (const char* b : bones) {
      if (std::string(a) == b) {
        continue;
      }
      double nearest = kInf;
      for (const Vec3& v : part(b).mesh.vertices) {
        nearest = std::min(nearest, bvh.closest_point(v).signed_distance);
      }
      EXPECT_GT(nearest, 0.002) << b << " vertex within 2 mm of (or inside) " << a;
    }
  }
}

TEST(ProceduralKnee, AnatomyInTheDocumentedFrame) {
  const Vec3 femur = centroid(part("femur").mesh);
  const Vec3 tibia = centroid(part("tibia").mesh);
  EXPECT_GT(part("femur").mesh.bounds().min().z(), 0.0);            // above the joint line
  EXPECT_LT(part("tibia").mesh.bounds().max().z(), 0.0);            // below it
  EXPECT_GT(centroid(part("patella").mesh).y(), femur.y() + 0.03);  // in front
  EXPECT_GT(centroid(part("fibula").mesh).x(), tibia.x() + 0.02);   // lateral
  EXPECT_LT(centroid(part("hamstrings").mesh).y(), femur.y() - 0.02);
  EXPECT_GT(centroid(part("quadriceps").mesh).y(), femur.y() + 0.02);
  EXPECT_LT(centroid(part("gastrocnemius").mesh).y(), tibia.y() - 0.03);
  EXPECT_LT(centroid(part("medial_collateral_ligament").mesh).x(), -0.04);
  EXPECT_GT(centroid(part("lateral_collateral_ligament").mesh).x(), 0.04);
  // The tendon runs from the patella's lower pole down to the tibia.
  const Box3 tendon = part("patellar_tendon").mesh.bounds();
  EXPECT_GT(tendon.max().z(), part("patella").mesh.bounds().min().z());
  EXPECT_LT(tendon.min().z(), -0.03);
}

TEST(ProceduralKnee, OptionsScaleAndSkin) {
  ProceduralKneeOptions o;
  o.include_skin = false;
  const auto no_skin = make_procedural_knee(o);
  ASSERT_EQ(no_skin.size(), knee().size() - 1);
  EXPECT_EQ(no_skin.back().name, "lateral_collateral_ligament");
  EXPECT_EQ(no_skin[0].mesh.vertices, knee()[0].mesh.vertices);
  o.resolution_scale = 1.5;
  std::size_t fine = 0;
  std::size_t coarse = 0;
  const auto finer = make_procedural_knee(o);
  for (std::size_t i = 0; i < finer.size(); ++i) {
    fine += finer[i].mesh.vertex_count();
    coarse += knee()[i].mesh.vertex_count();
  }
  // Surface vertices grow with the square of the resolution: 2.25x here.
  EXPECT_GT(static_cast<double>(fine), 1.8 * static_cast<double>(coarse));
  EXPECT_LT(static_cast<double>(fine), 2.7 * static_cast<double>(coarse));
  o.resolution_scale = 0.0;
  EXPECT_THROW((void)make_procedural_knee(o), Error);
}

}  // namespace
}  // namespace hapsim
