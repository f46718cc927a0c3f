#include "hapsim/render/render_scene.h"

#include "hapsim/core/error.h"
#include "hapsim/geometry/mesh_validation.h"

#include <algorithm>
#include <array>
#include <atomic>
#include <cmath>

namespace hapsim {
namespace {

// Stamps are unique across all scenes (and copies of scenes), so equal stamps mean equal data
// and a renderer never mistakes one mesh's upload for another's.
std::uint64_t next_stamp() {
  static std::atomic<std::uint64_t> counter{0};
  return ++counter;
}

Vec3f hsv_to_rgb(float h, float s, float v) {
  const float c = v * s;
  const float hp = h * 6.0f;
  const float x = c * (1.0f - std::fabs(std::fmod(hp, 2.0f) - 1.0f));
  Vec3f rgb;
  switch (static_cast<int>(hp) % 6) {
    case 0:
      rgb = {c, x, 0};
      break;
    case 1:
      rgb = {x, c, 0};
      break;
    case 2:
      rgb = {0, c, x};
      break;
    case 3:
      rgb = {0, x, c};
      break;
    case 4:
      rgb = {x, 0, c};
      break;
    default:
      rgb = {c, 0, x};
      break;
  }
  return rgb + Vec3f::Constant(v - c);
}

}  // namespace

Vec3f palette_colour(int i) {
  // Tableau 10: designed so neighbouring categories stay distinguishable.
  static constexpr std::array<std::array<float, 3>, 10> kTable = {{{0.306f, 0.475f, 0.655f},
                                                                   {0.949f, 0.557f, 0.169f},
                                                                   {0.882f, 0.341f, 0.349f},
                                                                   {0.463f, 0.718f, 0.698f},
                                                                   {0.349f, 0.631f, 0.310f},
                                                                   {0.929f, 0.788f, 0.282f},
                                                                   {0.690f, 0.478f, 0.631f},
                                                                   {1.000f, 0.616f, 0.655f},
                                                                   {0.612f, 0.459f, 0.373f},
                                                                   {0.729f, 0.690f, 0.675f}}};
  if (i < 0) {
    i = -i;
  }
  if (i < static_cast<int>(kTable.size())) {
    const auto& c = kTable[static_cast<std::size_t>(i)];
    return Vec3f(c[0], c[1], c[2]);
  }
  // Golden-angle hue steps never repeat and keep consecutive indices far apart on the wheel;
  // alternating saturation/value separates colours of similar hue.
  const float golden = 0.618033988749895f;
  const float hue = std::fmod(0.1f + static_cast<float>(i) * golden, 1.0f);
  const bool odd = (i % 2) != 0;
  return hsv_to_rgb(hue, odd ? 0.55f : 0.75f, odd ? 0.95f : 0.8f);
}

MeshId RenderScene::add_mesh(const TriangleMesh& mesh_M, const Vec3f& colour,
                             const Iso3& X_world_mesh) {
  RenderMesh& m = meshes_.emplace_back();
  m.colour = colour;
  m.X_world_mesh = X_world_mesh;
  m.geometry_ = mesh_M;
  if (m.geometry_.vertex_normals.size() != m.geometry_.vertices.size()) {
    m.geometry_.compute_vertex_normals();
  }
  m.lod_levels_ = build_lod_levels(m.geometry_);
  if (!m.geometry_.vertices.empty()) {
    const Box3 box = m.geometry_.bounds();
    m.bounding_centre_M_ = box.center();
    for (const Vec3& v : m.geometry_.vertices) {
      m.bounding_radius_m_ = std::max(m.bounding_radius_m_, (v - m.bounding_centre_M_).norm());
    }
  }
  const MeshReport report = validate_mesh(m.geometry_);
  m.closed_ = report.closed && report.inverted_components == 0 && report.signed_volume > 0.0;
  m.topology_stamp_ = next_stamp();
  m.vertex_stamp_ = next_stamp();
  return static_cast<MeshId>(meshes_.size() - 1);
}

MeshId RenderScene::add_mesh(std::span<const Vec3> positions_M,
                             std::span<const TriangleIndices> triangles, const Vec3f& colour,
                             const Iso3& X_world_mesh) {
  TriangleMesh mesh;
  mesh.vertices.assign(positions_M.begin(), positions_M.end());
  mesh.triangles.assign(triangles.begin(), triangles.end());
  for (const TriangleIndices& t : mesh.triangles) {
    for (const std::uint32_t v : t) {
      if (v >= mesh.vertices.size()) {
        throw Error("RenderScene::add_mesh",
                    "triangle index " + std::to_string(v) + " out of range (" +
                        std::to_string(mesh.vertices.size()) + " vertices)");
      }
    }
  }
  return add_mesh(mesh, colour, X_world_mesh);
}

RenderMesh& RenderScene::checked(MeshId id, const char* where) {
  if (id >= meshes_.size()) {
    throw Error(where, "no mesh with id " + std::to_string(id) + " (" +
                           std::to_string(meshes_.size()) + " meshes)");
  }
  return meshes_[id];
}

void RenderScene::update_positions(MeshId id, std::span<const Vec3> positions_M) {
  RenderMesh& m = checked(id, "RenderScene::update_positions");
  if (positions_M.size() != m.geometry_.vertices.size()) {
    throw Error("RenderScene::update_positions",
                "mesh " + std::to_string(id) + " has " +
                    std::to_string(m.geometry_.vertices.size()) + " vertices, got " +
                    std::to_string(positions_M.size()) + " positions");
  }
  std::copy(positions_M.begin(), positions_M.end(), m.geometry_.vertices.begin());
  m.geometry_.compute_vertex_normals();  // assign() reuses the normals' storage
  m.vertex_stamp_ = next_stamp();
}

void RenderScene::drop_lod_levels(MeshId id) {
  RenderMesh& m = checked(id, "RenderScene::drop_lod_levels");
  if (!m.lod_levels_.empty()) {
    m.lod_levels_.clear();
    m.topology_stamp_ = next_stamp();
  }
}

void RenderScene::set_vertex_colours(MeshId id, std::span<const Vec3f> colours) {
  RenderMesh& m = checked(id, "RenderScene::set_vertex_colours");
  if (!colours.empty() && colours.size() != m.geometry_.vertices.size()) {
    throw Error("RenderScene::set_vertex_colours", "mesh " + std::to_string(id) + " has " +
                                                       std::to_string(m.geometry_.vertices.size()) +
                                                       " vertices, got " +
                                                       std::to_string(colours.size()) + " colours");
  }
  m.vertex_colours_.assign(colours.begin(), colours.end());
  m.vertex_stamp_ = next_stamp();
}

RenderMesh& RenderScene::mesh(MeshId id) {
  return checked(id, "RenderScene::mesh");
}

const RenderMesh& RenderScene::mesh(MeshId id) const {
  return const_cast<RenderScene*>(this)->checked(id, "RenderScene::mesh");
}

Box3 RenderScene::bounds_world() const {
  Box3 box;
  for (const RenderMesh& m : meshes_) {
    if (!m.visible) {
      continue;
    }
    for (const Vec3& v : m.geometry_.vertices) {
      box.extend(m.X_world_mesh * v);
    }
  }
  for (const RenderSphere& s : spheres) {
    box.extend(s.centre_world - Vec3::Constant(s.radius_m));
    box.extend(s.centre_world + Vec3::Constant(s.radius_m));
  }
  for (const RenderCapsule& c : capsules) {
    for (const Vec3& p : {c.a_world, c.b_world}) {
      box.extend(p - Vec3::Constant(c.radius_m));
      box.extend(p + Vec3::Constant(c.radius_m));
    }
  }
  return box;
}

}  // namespace hapsim
