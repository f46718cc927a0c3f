#include "hapsim/geometry/triangle_mesh.h"

#include <algorithm>
#include <cmath>

namespace hapsim {

Vec3 TriangleMesh::face_normal_area2(std::size_t t) const {
  const auto [a, b, c] = corners(t);
  return (b - a).cross(c - a);
}

Vec3 TriangleMesh::face_normal(std::size_t t) const {
  const Vec3 n = face_normal_area2(t);
  const double len = n.norm();
  return len > 0.0 ? Vec3(n / len) : Vec3::Zero();
}

Box3 TriangleMesh::bounds() const {
  Box3 box;  // empty by default
  for (const Vec3& v : vertices) {
    box.extend(v);
  }
  return box;
}

double TriangleMesh::surface_area() const {
  double area = 0.0;
  for (std::size_t t = 0; t < triangles.size(); ++t) {
    area += 0.5 * face_normal_area2(t).norm();
  }
  return area;
}

double TriangleMesh::signed_volume() const {
  double six_volume = 0.0;
  for (std::size_t t = 0; t < triangles.size(); ++t) {
    const auto [a, b, c] = corners(t);
    six_volume += a.dot(b.cross(c));
  }
  return six_volume / 6.0;
}

void TriangleMesh::compute_vertex_normals() {
  vertex_normals.assign(vertices.size(), Vec3::Zero());
  for (std::size_t t = 0; t < triangles.size(); ++t) {
    const Vec3 n = face_normal(t);
    if (n.isZero()) {
      continue;
    }
    const TriangleIndices& tri = triangles[t];
    for (int k = 0; k < 3; ++k) {
      const Vec3& p = vertices[tri[k]];
      const Vec3 e1 = (vertices[tri[(k + 1) % 3]] - p).normalized();
      const Vec3 e2 = (vertices[tri[(k + 2) % 3]] - p).normalized();
      const double angle = std::acos(std::clamp(e1.dot(e2), -1.0, 1.0));
      vertex_normals[tri[k]] += angle * n;
    }
  }
  for (Vec3& n : vertex_normals) {
    const double len = n.norm();
    if (len > 0.0) {
      n /= len;
    }
  }
}

void TriangleMesh::transform(const Iso3& X_new_old) {
  for (Vec3& v : vertices) {
    v = X_new_old * v;
  }
  const Mat3 R = X_new_old.linear();
  for (Vec3& n : vertex_normals) {
    n = R * n;
  }
}

void TriangleMesh::scale(double factor) {
  for (Vec3& v : vertices) {
    v *= factor;
  }
  if (factor < 0.0) {  // a mirror flips orientation; keep triangles outward
    for (TriangleIndices& t : triangles) {
      std::swap(t[1], t[2]);
    }
    for (Vec3& n : vertex_normals) {
      n = -n;
    }
  }
}

void TriangleMesh::append(const TriangleMesh& other) {
  const bool had_normals = !vertex_normals.empty() || !other.vertex_normals.empty();
  const auto offset = static_cast<std::uint32_t>(vertices.size());
  vertices.insert(vertices.end(), other.vertices.begin(), other.vertices.end());
  for (const TriangleIndices& t : other.triangles) {
    triangles.push_back({t[0] + offset, t[1] + offset, t[2] + offset});
  }
  vertex_normals.clear();
  if (had_normals) {
    compute_vertex_normals();
  }
}

std::size_t TriangleMesh::remove_unused_vertices() {
  std::vector<std::uint32_t> remap(vertices.size(), kNoTriangle);
  for (const TriangleIndices& t : triangles) {
    for (std::uint32_t v : t) {
      remap[v] = 0;
    }
  }
  std::uint32_t next = 0;
  std::vector<Vec3> kept;
  kept.reserve(vertices.size());
  for (std::size_t v = 0; v < vertices.size(); ++v) {
    if (remap[v] == 0) {
      remap[v] = next++;
      kept.push_back(vertices[v]);
    }
  }
  const std::size_t removed = vertices.size() - kept.size();
  if (removed == 0) {
    return 0;
  }
  for (TriangleIndices& t : triangles) {
    for (std::uint32_t& v : t) {
      v = remap[v];
    }
  }
  vertices = std::move(kept);
  if (!vertex_normals.empty()) {
    compute_vertex_normals();
  }
  return removed;
}

}  // namespace hapsim
