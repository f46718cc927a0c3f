// Display levels of detail (geometry/mesh_lod.h): each level's reported error bounds how far it
// really strays from the full mesh — the exact Hausdorff distance (collision/hausdorff.h, the
// exact closest-point query) both ways — on the default knee's real parts and a bumpy sphere.
#include "hapsim/geometry/mesh_lod.h"

#include "hapsim/collision/hausdorff.h"
#include "hapsim/geometry/mesh_io.h"
#include "hapsim/geometry/procedural.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <map>
#include <random>
#include <set>
#include <string>

namespace hapsim {
namespace {

const std::filesystem::path kKnee =
    std::filesystem::path(HAPSIM_SOURCE_DIR) / "scenes" / "knee_vhf_small";

TriangleMesh level_mesh(const TriangleMesh& full, const LodLevel& level) {
  TriangleMesh m;
  m.vertices = full.vertices;
  m.triangles = level.triangles;
  m.remove_unused_vertices();
  return m;
}

// Every level: fewer triangles than the one before, indices into the full mesh, an error that
// grows with coarseness, stays under the build's limit, and bounds the exact Hausdorff distance.
void expect_levels_bounded(const TriangleMesh& full, const std::string& name) {
  const LodBuildOptions options;
  const std::vector<LodLevel> levels = build_lod_levels(full, options);
  ASSERT_FALSE(levels.empty()) << name;
  const double extent_m = full.bounds().sizes().maxCoeff();
  std::size_t previous_triangles = full.triangle_count();
  double previous_error_m = 0.0;
  for (std::size_t i = 0; i < levels.size(); ++i) {
    const LodLevel& level = levels[i];
    SCOPED_TRACE(name + " level " + std::to_string(i + 1));
    EXPECT_LT(level.triangles.size(), previous_triangles);
    EXPECT_GE(level.error_m, previous_error_m);
    EXPECT_LE(level.error_m, options.max_error_rel * extent_m * (1.0 + 1e-6));
    for (const TriangleIndices& t : level.triangles) {
      for (const std::uint32_t v : t) {
        ASSERT_LT(v, full.vertex_count());
      }
    }
    const HausdorffDistance h = hausdorff_distance(level_mesh(full, level), full);
    // The sampled distance is a lower bound of the true one: it must not exceed the reported
    // error (plus float rounding of the simplifier's positions, 1 µm).
    EXPECT_LE(h.sampled_m(), level.error_m + 1e-6)  // NOLINT
        << "(ratio " << h.sampled_m() / level.error_m << ") "
        << "hausdorff " << h.sampled_m() * 1e3 << " mm, reported " << level.error_m * 1e3 << " mm, "
        << level.triangles.size() << " of " << full.triangle_count() << " triangles";
    previous_triangles = level.triangles.size();
    previous_error_m = level.error_m;
  }
}

TEST(MeshLod, DefaultKneePartsLevelsStayWithinTheirReportedError) {
  MeshLoadOptions load;
  load.scale = 1e-3;
  int parts = 0;
  for (const auto& entry : std::filesystem::directory_iterator(kKnee)) {
    if (entry.path().extension() == ".stl") {
      const TriangleMesh part = load_mesh(entry.path(), load);
      if (part.triangle_count() >= LodBuildOptions{}.min_triangles) {
        expect_levels_bounded(part, entry.path().filename().string());
        ++parts;
      }
    }
  }
  EXPECT_GE(parts, 20);
}

TEST(MeshLod, BumpySphereLevelsStayWithinTheirReportedError) {
  expect_levels_bounded(make_bumpy_sphere(20000), "bumpy sphere");
}

TEST(MeshLod, SmallMeshHasNoCoarserLevel) {
  EXPECT_TRUE(build_lod_levels(make_box(Vec3::Ones())).empty());
}

// A cut (open) mesh keeps its border: every border vertex of the full mesh is in every level,
// so no gap opens along the cut however coarse the level drawn.
TEST(MeshLod, OpenMeshKeepsItsBorderInEveryLevel) {
  TriangleMesh half = make_uv_sphere(1.0, 64, 32);
  std::erase_if(half.triangles, [&](const TriangleIndices& t) {
    return half.vertices[t[0]].z() + half.vertices[t[1]].z() + half.vertices[t[2]].z() < 0.0;
  });
  half.remove_unused_vertices();
  std::map<std::pair<std::uint32_t, std::uint32_t>, int> edge_uses;
  for (const TriangleIndices& t : half.triangles) {
    for (int k = 0; k < 3; ++k) {
      const std::uint32_t a = t[k];
      const std::uint32_t b = t[(k + 1) % 3];
      ++edge_uses[{std::min(a, b), std::max(a, b)}];
    }
  }
  std::set<std::uint32_t> border;
  for (const auto& [edge, uses] : edge_uses) {
    if (uses == 1) {
      border.insert(edge.first);
      border.insert(edge.second);
    }
  }
  ASSERT_GT(border.size(), 32u);
  const std::vector<LodLevel> levels = build_lod_levels(half);
  ASSERT_FALSE(levels.empty());
  for (const LodLevel& level : levels) {
    std::set<std::uint32_t> used;
    for (const TriangleIndices& t : level.triangles) {
      used.insert(t.begin(), t.end());
    }
    for (const std::uint32_t v : border) {
      EXPECT_TRUE(used.count(v) == 1) << "border vertex " << v << " lost";
    }
  }
}

// Vertices a 16-entry FIFO post-transform cache misses drawing `triangles` in order (the classic
// model of GPU vertex reuse; a software rasteriser's batch reuse behaves alike).
std::size_t fifo_misses(const std::vector<TriangleIndices>& triangles) {
  std::vector<std::uint32_t> fifo;
  std::size_t misses = 0;
  for (const TriangleIndices& t : triangles) {
    for (const std::uint32_t v : t) {
      if (std::find(fifo.begin(), fifo.end(), v) == fifo.end()) {
        ++misses;
        fifo.push_back(v);
        if (fifo.size() > 16) {
          fifo.erase(fifo.begin());
        }
      }
    }
  }
  return misses;
}

// The draw order of the full mesh: the same triangles, each with its winding as given, and far
// fewer vertices shaded again than in a shuffled order.
TEST(VertexCacheOrder, KeepsEveryTriangleAndItsWindingAndReusesVertices) {
  TriangleMesh sphere = make_uv_sphere(1.0, 48, 24);
  std::mt19937 rng(7);
  std::shuffle(sphere.triangles.begin(), sphere.triangles.end(), rng);
  const std::vector<TriangleIndices> ordered =
      vertex_cache_order(sphere.triangles, sphere.vertex_count());
  // Each triangle rotated to start at its smallest index keeps its winding and compares.
  const auto canonical = [](std::vector<TriangleIndices> ts) {
    for (TriangleIndices& t : ts) {
      std::rotate(t.begin(), std::min_element(t.begin(), t.end()), t.end());
    }
    std::sort(ts.begin(), ts.end());
    return ts;
  };
  EXPECT_EQ(canonical(ordered), canonical(sphere.triangles));
  const std::size_t shuffled = fifo_misses(sphere.triangles);
  const std::size_t reordered = fifo_misses(ordered);
  EXPECT_LT(2 * reordered, shuffled) << reordered << " against " << shuffled;
}

}  // namespace
}  // namespace hapsim
