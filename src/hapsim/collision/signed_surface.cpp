#include "hapsim/collision/signed_surface.h"

#include <algorithm>
#include <cmath>

namespace hapsim {
namespace {

// Vertex-to-triangle incidence in compressed rows: triangles of vertex v are
// tris[offsets[v] .. offsets[v+1]).
struct Incidence {
  std::vector<std::uint32_t> offsets;
  std::vector<std::uint32_t> tris;
};

Incidence build_incidence(const TriangleMesh& mesh) {
  Incidence inc;
  inc.offsets.assign(mesh.vertices.size() + 1, 0);
  for (const TriangleIndices& t : mesh.triangles) {
    for (std::uint32_t v : t) {
      ++inc.offsets[v + 1];
    }
  }
  for (std::size_t v = 0; v < mesh.vertices.size(); ++v) {
    inc.offsets[v + 1] += inc.offsets[v];
  }
  inc.tris.resize(inc.offsets.back());
  std::vector<std::uint32_t> fill(inc.offsets.begin(), inc.offsets.end() - 1);
  for (std::uint32_t t = 0; t < mesh.triangles.size(); ++t) {
    for (std::uint32_t v : mesh.triangles[t]) {
      inc.tris[fill[v]++] = t;
    }
  }
  return inc;
}

bool has_vertex(const TriangleIndices& t, std::uint32_t v) {
  return t[0] == v || t[1] == v || t[2] == v;
}

}  // namespace

SignedSurface::SignedSurface(const TriangleMesh& mesh) {
  const Incidence inc = build_incidence(mesh);
  neighbours_.assign(mesh.triangles.size(), {kNoTriangle, kNoTriangle, kNoTriangle});
  for (std::uint32_t t = 0; t < mesh.triangles.size(); ++t) {
    const TriangleIndices& tri = mesh.triangles[t];
    for (int e = 0; e < 3; ++e) {
      const std::uint32_t u = tri[static_cast<std::size_t>(e)];
      const std::uint32_t v = tri[static_cast<std::size_t>((e + 1) % 3)];
      std::uint32_t found = kNoTriangle;
      int count = 0;
      for (std::uint32_t k = inc.offsets[u]; k < inc.offsets[u + 1]; ++k) {
        const std::uint32_t other = inc.tris[k];
        if (other != t && has_vertex(mesh.triangles[other], v)) {
          found = other;
          ++count;
        }
      }
      if (count == 0) {
        ++open_edges_;
      } else if (count > 1) {
        found = kNonManifold;
        non_manifold_edges_.emplace(std::uint64_t{t} * 3 + static_cast<std::uint64_t>(e),
                                    Vec3::Zero());
      }
      neighbours_[t][static_cast<std::size_t>(e)] = found;
    }
  }
  update_normals(mesh);
}

void SignedSurface::update_normals(const TriangleMesh& mesh) {
  vertex_pseudo_normals_.assign(mesh.vertices.size(), Vec3::Zero());
  for (std::size_t t = 0; t < mesh.triangles.size(); ++t) {
    const Vec3 n = mesh.face_normal(t);
    if (n.isZero()) {
      continue;
    }
    const TriangleIndices& tri = mesh.triangles[t];
    for (std::size_t k = 0; k < 3; ++k) {
      const Vec3& p = mesh.vertices[tri[k]];
      const Vec3 e1 = mesh.vertices[tri[(k + 1) % 3]] - p;
      const Vec3 e2 = mesh.vertices[tri[(k + 2) % 3]] - p;
      // Incident angle via atan2: accurate for tiny and near-flat angles alike.
      const double angle = std::atan2(e1.cross(e2).norm(), e1.dot(e2));
      vertex_pseudo_normals_[tri[k]] += angle * n;
    }
  }
  // Non-manifold edges: the sum of the unit normals of every triangle on the edge.
  if (non_manifold_edges_.empty()) {
    return;
  }
  const Incidence inc = build_incidence(mesh);
  for (auto& [key, normal] : non_manifold_edges_) {
    const auto t = static_cast<std::uint32_t>(key / 3);
    const auto e = static_cast<std::size_t>(key % 3);
    const std::uint32_t u = mesh.triangles[t][e];
    const std::uint32_t v = mesh.triangles[t][(e + 1) % 3];
    normal = Vec3::Zero();
    for (std::uint32_t k = inc.offsets[u]; k < inc.offsets[u + 1]; ++k) {
      if (has_vertex(mesh.triangles[inc.tris[k]], v)) {
        normal += mesh.face_normal(inc.tris[k]);
      }
    }
  }
}

Vec3 SignedSurface::edge_pseudo_normal(const TriangleMesh& mesh, std::uint32_t triangle,
                                       int edge) const {
  const std::uint32_t other = neighbours_[triangle][static_cast<std::size_t>(edge)];
  if (other == kNoTriangle) {
    return mesh.face_normal(triangle);
  }
  if (other == kNonManifold) {
    const auto it =
        non_manifold_edges_.find(std::uint64_t{triangle} * 3 + static_cast<std::uint64_t>(edge));
    return it != non_manifold_edges_.end() ? it->second : mesh.face_normal(triangle);
  }
  return mesh.face_normal(triangle) + mesh.face_normal(other);
}

SurfacePoint SignedSurface::resolve(const TriangleMesh& mesh, const Vec3& p, std::uint32_t triangle,
                                    const TriangleClosest& closest) const {
  const TriangleIndices& tri = mesh.triangles[triangle];
  Vec3 pseudo_normal = Vec3::Zero();
  switch (closest.feature) {
    case TriangleFeature::kVertexA:
      pseudo_normal = vertex_pseudo_normals_[tri[0]];
      break;
    case TriangleFeature::kVertexB:
      pseudo_normal = vertex_pseudo_normals_[tri[1]];
      break;
    case TriangleFeature::kVertexC:
      pseudo_normal = vertex_pseudo_normals_[tri[2]];
      break;
    case TriangleFeature::kEdgeAB:
      pseudo_normal = edge_pseudo_normal(mesh, triangle, 0);
      break;
    case TriangleFeature::kEdgeBC:
      pseudo_normal = edge_pseudo_normal(mesh, triangle, 1);
      break;
    case TriangleFeature::kEdgeCA:
      pseudo_normal = edge_pseudo_normal(mesh, triangle, 2);
      break;
    case TriangleFeature::kFace:
      pseudo_normal = mesh.face_normal(triangle);
      break;
  }
  SurfacePoint out;
  out.point = closest.point;
  out.triangle = triangle;
  const Vec3 offset = p - closest.point;
  const double distance = std::sqrt(closest.distance_sq);
  const bool outside = offset.dot(pseudo_normal) >= 0.0;
  out.signed_distance = outside ? distance : -distance;
  // Off the surface the direction to p is the exact normal of the distance field; on it, fall
  // back to the pseudo-normal.
  const double len = pseudo_normal.norm();
  if (distance > 1e-12 * (1.0 + closest.point.norm())) {
    out.normal = (outside ? offset : Vec3(-offset)) / distance;
  } else if (len > 0.0) {
    out.normal = pseudo_normal / len;
  } else {
    out.normal = Vec3::UnitZ();
  }
  return out;
}

std::size_t SignedSurface::memory_bytes() const {
  return neighbours_.size() * sizeof(TriangleIndices) +
         vertex_pseudo_normals_.size() * sizeof(Vec3) +
         non_manifold_edges_.size() * (sizeof(std::uint64_t) + sizeof(Vec3) + 16);
}

}  // namespace hapsim
