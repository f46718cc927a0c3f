#include "hapsim/render/creased_normals.h"

#include <cmath>

namespace hapsim {

TriangleMesh with_creased_normals(const TriangleMesh& mesh, double crease_rad) {
  const std::size_t n_tri = mesh.triangles.size();
  // Area-weighted face normals (the cross product's length is twice the area).
  std::vector<Vec3> face_n(n_tri);
  for (std::size_t t = 0; t < n_tri; ++t) {
    const TriangleIndices& tri = mesh.triangles[t];
    face_n[t] = (mesh.vertices[tri[1]] - mesh.vertices[tri[0]])
                    .cross(mesh.vertices[tri[2]] - mesh.vertices[tri[0]]);
  }
  // The faces around each vertex (compressed rows).
  std::vector<std::uint32_t> start(mesh.vertices.size() + 1, 0);
  for (const TriangleIndices& tri : mesh.triangles) {
    for (const std::uint32_t v : tri) {
      ++start[v + 1];
    }
  }
  for (std::size_t v = 0; v < mesh.vertices.size(); ++v) {
    start[v + 1] += start[v];
  }
  std::vector<std::uint32_t> faces(start.back());
  std::vector<std::uint32_t> fill(start.begin(), start.end() - 1);
  for (std::size_t t = 0; t < n_tri; ++t) {
    for (const std::uint32_t v : mesh.triangles[t]) {
      faces[fill[v]++] = static_cast<std::uint32_t>(t);
    }
  }
  const double cos_crease = std::cos(crease_rad);
  TriangleMesh out;
  out.vertices.reserve(3 * n_tri);
  out.vertex_normals.reserve(3 * n_tri);
  out.triangles.reserve(n_tri);
  for (std::size_t t = 0; t < n_tri; ++t) {
    const double own_len = face_n[t].norm();
    const Vec3 own = own_len > 0.0 ? Vec3(face_n[t] / own_len) : Vec3::UnitZ();
    const auto base = static_cast<std::uint32_t>(out.vertices.size());
    for (const std::uint32_t v : mesh.triangles[t]) {
      Vec3 n = Vec3::Zero();
      for (std::uint32_t k = start[v]; k < start[v + 1]; ++k) {
        const Vec3& other = face_n[faces[k]];
        const double len = other.norm();
        if (len > 0.0 && own.dot(other) >= cos_crease * len) {
          n += other;
        }
      }
      out.vertices.push_back(mesh.vertices[v]);
      out.vertex_normals.push_back(n.squaredNorm() > 0.0 ? Vec3(n.normalized()) : own);
    }
    out.triangles.push_back({base, base + 1, base + 2});
  }
  return out;
}

}  // namespace hapsim
