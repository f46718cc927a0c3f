#include "hapsim/geometry/procedural.h"

#include <algorithm>
#include <cmath>
#include <numbers>

namespace hapsim {
namespace {

// Shared latitude-longitude tessellation; radius_at(theta, phi) gives the surface.
template <typename RadiusFn>
TriangleMesh lat_long_mesh(int segments, int rings, RadiusFn radius_at) {
  TriangleMesh mesh;
  const double pi = std::numbers::pi;
  mesh.vertices.push_back(Vec3(0, 0, radius_at(0.0, 0.0)));  // north pole
  for (int r = 1; r < rings; ++r) {
    const double theta = pi * r / rings;
    for (int s = 0; s < segments; ++s) {
      const double phi = 2.0 * pi * s / segments;
      const double rad = radius_at(theta, phi);
      mesh.vertices.push_back(rad * Vec3(std::sin(theta) * std::cos(phi),
                                         std::sin(theta) * std::sin(phi), std::cos(theta)));
    }
  }
  mesh.vertices.push_back(Vec3(0, 0, -radius_at(pi, 0.0)));  // south pole
  const auto ring_vertex = [segments](int r, int s) {
    return static_cast<std::uint32_t>(1 + (r - 1) * segments + (s % segments));
  };
  const auto south = static_cast<std::uint32_t>(mesh.vertices.size() - 1);
  for (int s = 0; s < segments; ++s) {
    mesh.triangles.push_back({0, ring_vertex(1, s), ring_vertex(1, s + 1)});
  }
  for (int r = 1; r + 1 < rings; ++r) {
    for (int s = 0; s < segments; ++s) {
      const std::uint32_t a = ring_vertex(r, s);
      const std::uint32_t b = ring_vertex(r + 1, s);
      const std::uint32_t c = ring_vertex(r + 1, s + 1);
      const std::uint32_t d = ring_vertex(r, s + 1);
      mesh.triangles.push_back({a, b, c});
      mesh.triangles.push_back({a, c, d});
    }
  }
  for (int s = 0; s < segments; ++s) {
    mesh.triangles.push_back({south, ring_vertex(rings - 1, s + 1), ring_vertex(rings - 1, s)});
  }
  mesh.compute_vertex_normals();
  return mesh;
}

}  // namespace

TriangleMesh make_uv_sphere(double radius_m, int segments, int rings) {
  segments = std::max(segments, 3);
  rings = std::max(rings, 2);
  return lat_long_mesh(segments, rings, [radius_m](double, double) { return radius_m; });
}

TriangleMesh make_bumpy_sphere(std::size_t target_triangles, double radius_m, double bump_amplitude,
                               int bump_frequency) {
  // 2·s·(r−1) triangles with s ≈ 2r (roughly square cells at the equator).
  const double rings_f =
      std::sqrt(static_cast<double>(std::max<std::size_t>(target_triangles, 32)) / 4.0);
  const int rings = std::max(4, static_cast<int>(std::lround(rings_f)));
  const int segments = std::max(
      6,
      static_cast<int>(std::lround(static_cast<double>(target_triangles) / (2.0 * (rings - 1)))));
  const double k = bump_frequency;
  return lat_long_mesh(segments, rings, [=](double theta, double phi) {
    return radius_m * (1.0 + bump_amplitude * std::sin(k * theta) * std::sin(k * phi));
  });
}

TriangleMesh make_box(const Vec3& half_m) {
  TriangleMesh mesh;
  for (int i = 0; i < 8; ++i) {
    mesh.vertices.push_back(Vec3((i & 1) ? half_m.x() : -half_m.x(),
                                 (i & 2) ? half_m.y() : -half_m.y(),
                                 (i & 4) ? half_m.z() : -half_m.z()));
  }
  // Faces as quads (counter-clockwise seen from outside), split into two triangles each.
  const std::uint32_t quads[6][4] = {{0, 2, 3, 1}, {4, 5, 7, 6}, {0, 1, 5, 4},
                                     {2, 6, 7, 3}, {0, 4, 6, 2}, {1, 3, 7, 5}};
  for (const auto& q : quads) {
    mesh.triangles.push_back({q[0], q[1], q[2]});
    mesh.triangles.push_back({q[0], q[2], q[3]});
  }
  mesh.compute_vertex_normals();
  return mesh;
}

TriangleMesh make_sheet(int nodes_per_side, double size_m) {
  const int n = std::max(nodes_per_side, 2);
  TriangleMesh mesh;
  const double step = size_m / (n - 1);
  for (int j = 0; j < n; ++j) {
    for (int i = 0; i < n; ++i) {
      mesh.vertices.push_back(Vec3(-0.5 * size_m + i * step, -0.5 * size_m + j * step, 0.0));
    }
  }
  const auto at = [n](int i, int j) { return static_cast<std::uint32_t>(j * n + i); };
  for (int j = 0; j + 1 < n; ++j) {
    for (int i = 0; i + 1 < n; ++i) {
      mesh.triangles.push_back({at(i, j), at(i + 1, j), at(i + 1, j + 1)});
      mesh.triangles.push_back({at(i, j), at(i + 1, j + 1), at(i, j + 1)});
    }
  }
  mesh.compute_vertex_normals();
  return mesh;
}

}  // namespace hapsim
