// The tetrahedral mesh layer against answers worked out independently: a block's volume is the
// product of its sizes and its boundary has 2·(nx·ny + ny·nz + nx·nz)·2 triangles enclosing that
// volume; a regular tet's dihedral angle is acos(1/3) = 70.5288° and its aspect ratio 1; points
// embedded in the tets come back where they were, and move affinely with the nodes.
#include "hapsim/geometry/tet_mesh.h"
#include "hapsim/geometry/tet_embedding.h"

#include "hapsim/core/error.h"
#include "hapsim/geometry/mesh_validation.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <numbers>
#include <random>
#include <string>

namespace hapsim {
namespace {

constexpr double kPi = std::numbers::pi;

// (b−a)·((c−a)×(d−a))/6, written out here rather than taken from the code under test.
double orient_volume(const Vec3& a, const Vec3& b, const Vec3& c, const Vec3& d) {
  return (b - a).dot((c - a).cross(d - a)) / 6.0;
}

std::string error_of(const TetMesh& mesh, bool allow_disconnected = false) {
  try {
    validate_tet_mesh(mesh, "body.msh", allow_disconnected);
  } catch (const Error& e) {
    return e.what();
  }
  return "";
}

// A regular tetrahedron with edge `a`, positively oriented.
TetMesh regular_tet(double a) {
  TetMesh m;
  m.nodes = {Vec3(1, 1, 1), Vec3(1, -1, -1), Vec3(-1, 1, -1), Vec3(-1, -1, 1)};
  for (Vec3& p : m.nodes) {
    p *= a / std::sqrt(8.0);  // the edge of this tet is 2√2
  }
  m.tets = {{0, 1, 2, 3}};
  if (orient_volume(m.nodes[0], m.nodes[1], m.nodes[2], m.nodes[3]) < 0) {
    std::swap(m.tets[0][1], m.tets[0][2]);
  }
  return m;
}

TEST(TetMeshBlock, VolumeIsTheProductOfTheSizesAndEveryTetIsPositive) {
  const std::vector<std::pair<Vec3, std::array<int, 3>>> cases = {
      {Vec3(1, 1, 1), {1, 1, 1}},
      {Vec3(0.1, 0.02, 0.03), {5, 2, 3}},
      {Vec3(2.0, 0.5, 0.25), {4, 7, 1}}};
  for (const auto& [size, cells] : cases) {
    const TetMesh m = make_tet_block(size, cells);
    const auto n = static_cast<std::size_t>(cells[0] * cells[1] * cells[2]);
    ASSERT_EQ(m.tet_count(), 6 * n);
    ASSERT_EQ(m.node_count(),
              static_cast<std::size_t>((cells[0] + 1) * (cells[1] + 1) * (cells[2] + 1)));
    const double cell_volume = size.prod() / static_cast<double>(n);
    for (std::size_t t = 0; t < m.tet_count(); ++t) {
      const TetIndices& tet = m.tets[t];
      const double v =
          orient_volume(m.nodes[tet[0]], m.nodes[tet[1]], m.nodes[tet[2]], m.nodes[tet[3]]);
      ASSERT_GT(v, 0.0) << "tet " << t;
      // Six tets around the diagonal share a cube equally.
      EXPECT_NEAR(v, cell_volume / 6.0, 1e-12 * cell_volume);
      EXPECT_NEAR(m.signed_volume(t), v, 1e-15 * cell_volume);
    }
    EXPECT_NEAR(m.volume(), size.prod(), 1e-12 * size.prod());
    const Box3 box = m.bounds();
    EXPECT_TRUE(box.min().isZero(0.0));
    EXPECT_TRUE(box.max().isApprox(size, 1e-15));
    EXPECT_NO_THROW(validate_tet_mesh(m, "block"));
  }
}

TEST(TetMeshBlock, IsConformingEveryInnerFaceSharedByTwoTetsWoundOppositely) {
  const TetMesh m = make_tet_block(Vec3(1, 2, 3), {3, 2, 4});
  // Face (sorted nodes) -> the orientation parity of each use.
  std::map<std::array<std::uint32_t, 3>, std::vector<int>> uses;
  const int faces[4][3] = {{1, 2, 3}, {0, 3, 2}, {0, 1, 3}, {0, 2, 1}};
  for (const TetIndices& tet : m.tets) {
    for (const auto& f : faces) {
      std::array<std::uint32_t, 3> key{tet[static_cast<std::size_t>(f[0])],
                                       tet[static_cast<std::size_t>(f[1])],
                                       tet[static_cast<std::size_t>(f[2])]};
      // Parity of the permutation that sorts the face: opposite windings differ in parity.
      int swaps = 0;
      for (int i = 0; i < 3; ++i) {
        for (int j = 0; j < 2 - i; ++j) {
          if (key[static_cast<std::size_t>(j)] > key[static_cast<std::size_t>(j + 1)]) {
            std::swap(key[static_cast<std::size_t>(j)], key[static_cast<std::size_t>(j + 1)]);
            ++swaps;
          }
        }
      }
      uses[key].push_back(swaps % 2);
    }
  }
  std::size_t boundary = 0;
  for (const auto& [key, parities] : uses) {
    ASSERT_LE(parities.size(), 2u) << "a face shared by more than two tets";
    if (parities.size() == 2) {
      EXPECT_NE(parities[0], parities[1]) << "an inner face wound the same way twice";
    } else {
      ++boundary;
    }
  }
  EXPECT_EQ(boundary, 2u * (3 * 2 + 2 * 4 + 3 * 4) * 2);
}

TEST(TetMeshBoundary, OfABlockIsAClosedOutwardSurfaceOfTheBlocksVolume) {
  const Vec3 size(0.1, 0.06, 0.04);
  const std::array<int, 3> cells{5, 3, 2};
  const TetMesh m = make_tet_block(size, cells);
  const TetBoundary b = tet_boundary(m);
  const int nx = cells[0], ny = cells[1], nz = cells[2];
  EXPECT_EQ(b.surface.triangle_count(),
            static_cast<std::size_t>(2 * (nx * ny + ny * nz + nx * nz) * 2));
  // Boundary nodes: all grid nodes but the interior ones.
  EXPECT_EQ(b.surface.vertex_count(),
            m.node_count() - static_cast<std::size_t>((nx - 1) * (ny - 1) * (nz - 1)));
  EXPECT_NEAR(b.surface.signed_volume(), size.prod(), 1e-12 * size.prod());
  const MeshReport report = validate_mesh(b.surface);
  EXPECT_EQ(report.open_edges, 0u);
  EXPECT_EQ(report.non_manifold_edges, 0u);
  EXPECT_EQ(report.inconsistent_edges, 0u);
  EXPECT_EQ(report.components, 1u);
  ASSERT_EQ(b.node_of_vertex.size(), b.surface.vertex_count());
  ASSERT_EQ(b.tet_of_triangle.size(), b.surface.triangle_count());
  for (std::size_t v = 0; v < b.surface.vertex_count(); ++v) {
    EXPECT_EQ(b.surface.vertices[v], m.nodes[b.node_of_vertex[v]]);
  }
  for (std::size_t t = 0; t < b.surface.triangle_count(); ++t) {
    // Outward: the normal points away from the block's centre, along the face's axis.
    const Vec3 n = b.surface.face_normal(t);
    const auto [p0, p1, p2] = b.surface.corners(t);
    const Vec3 centroid = (p0 + p1 + p2) / 3.0;
    EXPECT_GT(n.dot(centroid - size / 2.0), 0.0);
    EXPECT_NEAR(n.cwiseAbs().maxCoeff(), 1.0, 1e-12);
    // Its tet holds all three corners.
    const TetIndices& tet = m.tets[b.tet_of_triangle[t]];
    for (const std::uint32_t v : b.surface.triangles[t]) {
      EXPECT_NE(std::find(tet.begin(), tet.end(), b.node_of_vertex[v]), tet.end());
    }
  }
}

TEST(TetMeshBoundary, OfOneTetIsItsFourFacesOutward) {
  const TetMesh m = regular_tet(1.0);
  const TetBoundary b = tet_boundary(m);
  ASSERT_EQ(b.surface.triangle_count(), 4u);
  EXPECT_NEAR(b.surface.signed_volume(), std::pow(1.0, 3) / (6.0 * std::sqrt(2.0)), 1e-12);
}

TEST(TetMeshQuality, RegularTetHasDihedralAcosOneThirdAndAspectOne) {
  for (const double edge : {1e-3, 1.0, 50.0}) {
    const TetMesh m = regular_tet(edge);
    const TetMeshQuality q = tet_mesh_quality(m);
    const double expected_deg = std::acos(1.0 / 3.0) * 180.0 / kPi;
    EXPECT_NEAR(expected_deg, 70.5288, 1e-4);
    EXPECT_NEAR(q.min_dihedral_deg, expected_deg, 1e-9);
    EXPECT_NEAR(q.max_dihedral_deg, expected_deg, 1e-9);
    EXPECT_NEAR(q.max_aspect_ratio, 1.0, 1e-12);
    const double volume = edge * edge * edge / (6.0 * std::sqrt(2.0));
    EXPECT_NEAR(q.total_volume_m3, volume, 1e-12 * volume);
    EXPECT_NEAR(q.min_volume_m3, volume, 1e-12 * volume);
    EXPECT_EQ(q.tets, 1u);
    EXPECT_EQ(q.nodes, 4u);
    EXPECT_EQ(q.components, 1u);
    EXPECT_EQ(q.inverted + q.degenerate + q.unused_nodes + q.out_of_range + q.non_finite, 0u);
  }
}

TEST(TetMeshQuality, CornerTetHasRightAndMagicAngles) {
  // (0,0,0),(1,0,0),(0,1,0),(0,0,1): 90° at the three axis edges, acos(1/√3) = 54.7356° where
  // the slanted face meets the others.
  TetMesh m;
  m.nodes = {Vec3(0, 0, 0), Vec3(1, 0, 0), Vec3(0, 1, 0), Vec3(0, 0, 1)};
  m.tets = {{0, 1, 2, 3}};
  const TetMeshQuality q = tet_mesh_quality(m);
  EXPECT_NEAR(q.min_dihedral_deg, std::acos(1.0 / std::sqrt(3.0)) * 180.0 / kPi, 1e-9);
  EXPECT_NEAR(q.max_dihedral_deg, 90.0, 1e-9);
  // Inradius 3V/A with V = 1/6 and A = 3·½ + (√3/4)·2; longest edge √2.
  const double inradius = 0.5 / (1.5 + std::sqrt(3.0) / 2.0);
  EXPECT_NEAR(q.max_aspect_ratio, std::sqrt(2.0) / (2.0 * std::sqrt(6.0) * inradius), 1e-12);
}

TEST(TetMeshQuality, CountsInvertedDegeneratePiecesUnusedAndUnusableTets) {
  TetMesh m = make_tet_block(Vec3(1, 1, 1), {2, 1, 1});  // 12 tets, 12 nodes
  std::swap(m.tets[3][0], m.tets[3][1]);                 // inverted
  m.tets[5] = {0, 0, 1, 2};                              // degenerate (a repeated node)
  // A second piece: one tet far away, and an unused node.
  const auto base = static_cast<std::uint32_t>(m.nodes.size());
  for (const Vec3& p : {Vec3(5, 5, 5), Vec3(6, 5, 5), Vec3(5, 6, 5), Vec3(5, 5, 6)}) {
    m.nodes.push_back(p);
  }
  m.tets.push_back({base, base + 1, base + 2, base + 3});
  m.nodes.emplace_back(9, 9, 9);
  m.tets.push_back({0, 1, 2, 999});  // out of range
  const TetMeshQuality q = tet_mesh_quality(m);
  EXPECT_EQ(q.tets, 14u);
  EXPECT_EQ(q.inverted, 1u);
  EXPECT_EQ(q.degenerate, 1u);
  EXPECT_EQ(q.components, 2u);
  EXPECT_EQ(q.unused_nodes, 1u);
  EXPECT_EQ(q.out_of_range, 1u);
  EXPECT_LT(q.min_volume_m3, 0.0);
  m.nodes[base] = Vec3(std::nan(""), 0, 0);
  EXPECT_EQ(tet_mesh_quality(m).non_finite, 1u);
}

TEST(TetMeshValidation, RefusesEachBadElementWithItsIndex) {
  const TetMesh good = make_tet_block(Vec3(3, 1, 1), {3, 1, 1});  // 18 tets of 1/6 m³
  ASSERT_EQ(error_of(good), "");

  TetMesh inverted = good;
  std::swap(inverted.tets[17][2], inverted.tets[17][3]);
  EXPECT_EQ(error_of(inverted), "body.msh: element 17: inverted (signed volume -0.167 m^3)");

  TetMesh out_of_range = good;
  out_of_range.tets[3][2] = 99;
  EXPECT_EQ(error_of(out_of_range),
            "body.msh: element 3: node 99 out of range (the mesh has 16 nodes)");

  // NaN in a node: the first element that uses it is named.
  TetMesh nan = good;
  const std::uint32_t node = good.tets[5][1];
  nan.nodes[node].y() = std::numeric_limits<double>::quiet_NaN();
  std::size_t first_user = 0;
  while (std::find(good.tets[first_user].begin(), good.tets[first_user].end(), node) ==
         good.tets[first_user].end()) {
    ++first_user;
  }
  EXPECT_EQ(error_of(nan), "body.msh: element " + std::to_string(first_user) + ": node " +
                               std::to_string(node) + " is not finite");

  TetMesh degenerate = good;
  degenerate.tets[8][3] = degenerate.tets[8][0];
  EXPECT_EQ(error_of(degenerate), "body.msh: element 8: degenerate (volume 0 m^3)");

  // Flat but not repeated: four coplanar nodes.
  TetMesh flat;
  flat.nodes = {Vec3(0, 0, 0), Vec3(1, 0, 0), Vec3(0, 1, 0), Vec3(1, 1, 0)};
  flat.tets = {{0, 1, 2, 3}};
  EXPECT_NE(error_of(flat).find("element 0: degenerate"), std::string::npos);

  // Inverted by a tiny amount: the value is printed as it is.
  TetMesh tiny = regular_tet(std::cbrt(1.2e-9 * 6.0 * std::sqrt(2.0)));
  std::swap(tiny.tets[0][0], tiny.tets[0][1]);
  EXPECT_EQ(error_of(tiny), "body.msh: element 0: inverted (signed volume -1.2e-09 m^3)");
}

TEST(TetMeshValidation, RefusesTetsThatOverlapThroughAFace) {
  const TetMesh good = make_tet_block(Vec3(1, 1, 1), {2, 1, 1});
  TetMesh duplicate = good;
  duplicate.tets.push_back(good.tets[4]);
  EXPECT_EQ(error_of(duplicate), "body.msh: element 12: duplicates element 4 (the same nodes)");

  // A fourth node on the same side of a face as its tet: the new tet folds over the old one.
  TetMesh folded;
  folded.nodes = {Vec3(0, 0, 0), Vec3(1, 0, 0), Vec3(0, 1, 0), Vec3(0, 0, 1), Vec3(0.1, 0.1, 0.5)};
  folded.tets = {{0, 1, 2, 3}, {0, 1, 2, 4}};
  EXPECT_EQ(error_of(folded),
            "body.msh: element 1: overlaps element 0 (both on the same side of "
            "their shared face, nodes 0, 1, 2)");

  // Three tets on one face.
  TetMesh fan = folded;
  fan.nodes.emplace_back(0, 0, -1);
  fan.tets = {{0, 1, 2, 3}, {0, 2, 1, 5}, {0, 1, 2, 4}};
  EXPECT_EQ(error_of(fan),
            "body.msh: element 2: its face (nodes 0, 1, 2) is shared by 3 "
            "elements; a face joins at most two");
}

TEST(TetMeshValidation, RefusesDisconnectedPiecesEmptyMeshesAndRegionMismatch) {
  TetMesh two = make_tet_block(Vec3(1, 1, 1), {1, 1, 1});
  TetMesh other = make_tet_block(Vec3(1, 1, 1), {2, 1, 1});
  const auto base = static_cast<std::uint32_t>(two.nodes.size());
  for (const Vec3& p : other.nodes) {
    two.nodes.push_back(p + Vec3(10, 0, 0));
  }
  for (TetIndices t : other.tets) {
    for (std::uint32_t& v : t) {
      v += base;
    }
    two.tets.push_back(t);
  }
  EXPECT_EQ(error_of(two),
            "body.msh: 2 disconnected pieces (element 0 and element 6 are not "
            "connected); one body is one piece");
  EXPECT_EQ(error_of(two, true), "");

  // Touching at one node is connected (tets sharing a node are).
  TetMesh touching = make_tet_block(Vec3(1, 1, 1), {1, 1, 1});
  const auto b2 = static_cast<std::uint32_t>(touching.nodes.size());
  touching.nodes.insert(touching.nodes.end(),
                        {Vec3(1, 1, 1), Vec3(2, 1, 1), Vec3(1, 2, 1), Vec3(1, 1, 2)});
  touching.tets.push_back({7, b2 + 1, b2 + 2, b2 + 3});  // node 7 is (1,1,1)
  ASSERT_EQ(touching.nodes[7], Vec3(1, 1, 1));
  EXPECT_EQ(error_of(touching), "");
  EXPECT_EQ(tet_mesh_quality(touching).components, 1u);
  EXPECT_EQ(tet_mesh_quality(touching).unused_nodes, 1u);  // the copy of (1,1,1)

  EXPECT_EQ(error_of(TetMesh{}), "body.msh: the mesh has no tetrahedra");

  TetMesh regions = make_tet_block(Vec3(1, 1, 1), {1, 1, 1});
  regions.regions = {1, 2};
  EXPECT_NE(error_of(regions).find("2 region values for 6 elements"), std::string::npos);
  regions.regions.assign(6, 3);
  EXPECT_EQ(error_of(regions), "");
  EXPECT_EQ(regions.region(4), 3);
}

TEST(TetMesh, ScaleAndTransformKeepTheShape) {
  TetMesh m = make_tet_block(Vec3(1, 2, 3), {2, 2, 2});
  m.scale(1e-3);
  EXPECT_NEAR(m.volume(), 6e-9, 1e-20);
  const Iso3 X =
      Iso3(Eigen::Translation3d(1, 2, 3) * Eigen::AngleAxisd(0.7, Vec3(1, 2, 3).normalized()));
  m.transform(X);
  EXPECT_NEAR(m.volume(), 6e-9, 1e-20);
  EXPECT_TRUE(m.nodes[0].isApprox(X.translation(), 1e-15));
  EXPECT_NO_THROW(validate_tet_mesh(m, "moved"));
}

TEST(TetMeshBall, IsAValidBallWhoseSurfaceIsOnTheSphere) {
  const double r = 0.05;
  const double sphere = 4.0 / 3.0 * kPi * r * r * r;
  double previous_gap = kInf;
  for (const std::size_t target : {500u, 5000u, 40000u}) {
    const TetMesh ball = make_tet_ball(r, target);
    ASSERT_NO_THROW(validate_tet_mesh(ball, "ball")) << target;
    const TetMeshQuality q = tet_mesh_quality(ball);
    EXPECT_EQ(q.inverted + q.degenerate + q.unused_nodes, 0u);
    EXPECT_GT(q.min_dihedral_deg, 3.0);
    EXPECT_GT(static_cast<double>(ball.tet_count()), 0.5 * static_cast<double>(target));
    EXPECT_LT(static_cast<double>(ball.tet_count()), 1.2 * static_cast<double>(target));
    const TetBoundary b = tet_boundary(ball);
    for (const Vec3& p : b.surface.vertices) {
      if (target >= 5000) {
        EXPECT_NEAR(p.norm(), r, 1e-12);
      } else {
        EXPECT_GT(p.norm(), 0.6 * r);  // between the staircase and the sphere
      }
    }
    for (const Vec3& p : ball.nodes) {
      EXPECT_LE(p.norm(), r * (1 + 1e-12));
    }
    const MeshReport report = validate_mesh(b.surface);
    EXPECT_EQ(report.open_edges + report.non_manifold_edges + report.inconsistent_edges, 0u);
    EXPECT_EQ(report.components, 1u);
    EXPECT_NEAR(b.surface.signed_volume(), ball.volume(), 1e-12 * sphere);
    // Inside the sphere: a little less volume, less as it is refined.
    const double gap = sphere - ball.volume();
    EXPECT_GT(gap, 0.0);
    EXPECT_LT(gap, (target >= 5000 ? 0.03 : 0.25) * sphere);
    EXPECT_LT(gap, previous_gap);
    previous_gap = gap;
  }
}

TEST(TetEmbedding, InteriorPointsComeBackWithWeightsInsideTheirTet) {
  const TetMesh ball = make_tet_ball(0.05, 5000);
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  std::vector<Vec3> points;
  while (points.size() < 2000) {
    const Vec3 p(u(rng), u(rng), u(rng));
    if (p.norm() < 0.9) {
      points.push_back(0.05 * p);  // inside the inscribed polyhedron for this resolution
    }
  }
  // The nodes themselves (on shared vertices, edges, faces) too.
  points.insert(points.end(), ball.nodes.begin(), ball.nodes.end());
  const std::vector<TetEmbedding> e = embed_points(ball, points);
  ASSERT_EQ(e.size(), points.size());
  for (std::size_t i = 0; i < points.size(); ++i) {
    ASSERT_LT(e[i].tet, ball.tet_count());
    EXPECT_EQ(e[i].distance_m, 0.0) << i;
    double sum = 0.0;
    for (const double w : e[i].barycentric) {
      EXPECT_GE(w, -1e-9);
      sum += w;
    }
    EXPECT_NEAR(sum, 1.0, 1e-12);
    EXPECT_LT((embedded_position(ball, ball.nodes, e[i]) - points[i]).norm(), 1e-15);
  }
}

TEST(TetEmbedding, OutsidePointsGoToTheNearestTetAndFollowAnAffineMotion) {
  const Vec3 size(0.1, 0.05, 0.02);
  TetMesh block = make_tet_block(size, {6, 3, 2});
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> u(-0.5, 1.5);
  std::vector<Vec3> points;
  for (int i = 0; i < 1000; ++i) {
    points.push_back(Vec3(u(rng), u(rng), u(rng)).cwiseProduct(size));
  }
  const std::vector<TetEmbedding> e = embed_points(block, points);
  const Box3 box(Vec3::Zero(), size);
  // A deformation every tet follows exactly: affine.
  Mat3 A;
  A << 1.1, 0.2, -0.1, 0.05, 0.9, 0.3, -0.2, 0.1, 1.2;
  const Vec3 shift(0.3, -0.1, 0.2);
  std::vector<Vec3> moved;
  for (const Vec3& p : block.nodes) {
    moved.push_back(A * p + shift);
  }
  for (std::size_t i = 0; i < points.size(); ++i) {
    // Distance to the union of the tets = distance to the box (independent of the tets).
    EXPECT_NEAR(e[i].distance_m, box.exteriorDistance(points[i]), 1e-12) << i;
    EXPECT_LT((embedded_position(block, block.nodes, e[i]) - points[i]).norm(), 1e-14);
    EXPECT_LT((embedded_position(block, moved, e[i]) - (A * points[i] + shift)).norm(), 1e-13);
    // The tet named is as near as the mesh: its closest point is at distance_m.
    const TetIndices& t = block.tets[e[i].tet];
    Box3 tet_box;
    for (const std::uint32_t v : t) {
      tet_box.extend(block.nodes[v]);
    }
    EXPECT_LE(tet_box.exteriorDistance(points[i]), e[i].distance_m + 1e-12);
  }
}

TEST(TetEmbedding, RefusesAMeshWithoutUsableTetsAndMarksNonFinitePoints) {
  TetMesh flat;
  flat.nodes = {Vec3(0, 0, 0), Vec3(1, 0, 0), Vec3(0, 1, 0), Vec3(1, 1, 0)};
  flat.tets = {{0, 1, 2, 3}};
  const std::vector<Vec3> p{Vec3(0.2, 0.2, 0.0)};
  EXPECT_THROW((void)embed_points(flat, p), Error);
  const TetMesh block = make_tet_block(Vec3(1, 1, 1), {1, 1, 1});
  const std::vector<Vec3> q{Vec3(std::nan(""), 0, 0), Vec3(0.5, 0.5, 0.5)};
  const auto e = embed_points(block, q);
  EXPECT_TRUE(std::isinf(e[0].distance_m));
  EXPECT_EQ(e[1].distance_m, 0.0);
}

}  // namespace
}  // namespace hapsim
