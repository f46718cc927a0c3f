// An indexed triangle mesh: the surface every body, tool and query works on.
// Plain data (MuJoCo style): fields are public, invariants are checked by mesh_validation.h.
#pragma once

#include "hapsim/core/types.h"

#include <cstddef>
#include <vector>

namespace hapsim {

struct TriangleMesh {
  /// Vertex positions in the mesh's own frame, metres.
  std::vector<Vec3> vertices;
  /// Triangles as vertex indices, counter-clockwise seen from outside.
  std::vector<TriangleIndices> triangles;
  /// Unit per-vertex normals (angle-weighted); empty until compute_vertex_normals().
  std::vector<Vec3> vertex_normals;

  [[nodiscard]] std::size_t vertex_count() const { return vertices.size(); }
  [[nodiscard]] std::size_t triangle_count() const { return triangles.size(); }
  [[nodiscard]] bool empty() const { return triangles.empty(); }

  /// The three corners of triangle `t`.
  [[nodiscard]] std::array<Vec3, 3> corners(std::size_t t) const {
    const TriangleIndices& tri = triangles[t];
    return {vertices[tri[0]], vertices[tri[1]], vertices[tri[2]]};
  }
  /// Unnormalised face normal (b-a)x(c-a); its length is twice the area.
  [[nodiscard]] Vec3 face_normal_area2(std::size_t t) const;
  /// Unit face normal, or zero for a degenerate triangle.
  [[nodiscard]] Vec3 face_normal(std::size_t t) const;

  [[nodiscard]] Box3 bounds() const;
  [[nodiscard]] double surface_area() const;
  /// Signed enclosed volume (divergence theorem); positive for a closed, outward-oriented mesh.
  [[nodiscard]] double signed_volume() const;

  /// Angle-weighted vertex normals (Thürmer & Wüthrich), robust to uneven triangulation.
  void compute_vertex_normals();
  /// Applies a rigid transform (and keeps normals consistent if present).
  void transform(const Iso3& X_new_old);
  /// Uniform scale, e.g. 1e-3 for a file in millimetres.
  void scale(double factor);
  /// Appends `other` (indices offset); normals are recomputed if either had them.
  void append(const TriangleMesh& other);
  /// Removes vertices no triangle uses and renumbers; returns how many were removed.
  std::size_t remove_unused_vertices();
};

}  // namespace hapsim
