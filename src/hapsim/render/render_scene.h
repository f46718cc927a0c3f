// What the renderer draws, as plain data with no GL types: meshes (registered once, positions
// updatable for deforming bodies), spheres (tools, proxies, bounding spheres), line segments
// (robot links, force arrows), shadow marks (an 'x' on the floor under the tool, for depth
// perception), a floor, lights and the display style. The app fills it from a world snapshot
// each frame; the renderer keeps GPU copies of meshes and re-uploads only what changed.
#pragma once

#include "hapsim/core/types.h"
#include "hapsim/geometry/mesh_lod.h"
#include "hapsim/geometry/triangle_mesh.h"

#include <cstdint>
#include <span>
#include <string>
#include <vector>

namespace hapsim {

/// How meshes are rasterised: vertices only, edges only, or filled triangles.
enum class DisplayMode { kPoints, kLines, kFaces };

/// Where mesh colours come from.
enum class ColourMode {
  kMeshColour,     ///< RenderMesh::colour, ignoring per-vertex colours.
  kVertexColours,  ///< Per-vertex colours where a mesh has them, else its colour.
  kPalette,        ///< palette_colour(mesh id): every mesh (segment) a distinct colour.
};

/// A distinct, well-separated colour for group/segment `i` (≥ 0): a 10-colour qualitative table,
/// then golden-angle hues for larger indices. RGB in [0, 1].
Vec3f palette_colour(int i);

using MeshId = std::uint32_t;

class RenderMesh {
 public:
  /// Appearance: change freely, no re-upload needed.
  Vec3f colour = Vec3f(0.8f, 0.8f, 0.8f);
  /// 1 opaque; less is blended over what is behind it, drawn after every opaque mesh.
  float opacity = 1.0f;
  /// World-from-mesh pose.
  Iso3 X_world_mesh = Iso3::Identity();
  bool visible = true;
  std::string name;

  /// Positions (mesh frame, metres), triangles and vertex normals (kept current).
  [[nodiscard]] const TriangleMesh& geometry() const { return geometry_; }
  /// A closed, consistently oriented surface with its normals outward (checked when added): its
  /// back faces can never be seen from outside, so the renderer culls them (half the triangles a
  /// software rasteriser must set up) and shades one side. Open sheets and cut meshes are false.
  [[nodiscard]] bool closed() const { return closed_; }
  /// Coarser triangle lists over the same vertices for drawing far away (geometry/mesh_lod.h),
  /// built when the mesh is added; empty for a small mesh. The renderer picks one per frame by
  /// its error on screen (render/lod_selection.h); new positions move every level alike.
  [[nodiscard]] const std::vector<LodLevel>& lod_levels() const { return lod_levels_; }
  /// A sphere around the mesh at rest, mesh frame: where the levels' screen error is measured.
  [[nodiscard]] const Vec3& bounding_centre_M() const { return bounding_centre_M_; }
  [[nodiscard]] double bounding_radius_m() const { return bounding_radius_m_; }
  /// Per-vertex RGB colours, empty or one per vertex.
  [[nodiscard]] const std::vector<Vec3f>& vertex_colours() const { return vertex_colours_; }
  /// Unique stamps of the current triangles and of the current positions/normals/colours; the
  /// renderer re-uploads a mesh whose stamps differ from the ones it uploaded.
  [[nodiscard]] std::uint64_t topology_stamp() const { return topology_stamp_; }
  [[nodiscard]] std::uint64_t vertex_stamp() const { return vertex_stamp_; }

 private:
  friend class RenderScene;
  TriangleMesh geometry_;
  std::vector<Vec3f> vertex_colours_;
  std::uint64_t topology_stamp_ = 0;
  std::uint64_t vertex_stamp_ = 0;
  bool closed_ = false;
  std::vector<LodLevel> lod_levels_;
  Vec3 bounding_centre_M_ = Vec3::Zero();
  double bounding_radius_m_ = 0.0;
};

struct RenderSphere {
  Vec3 centre_world = Vec3::Zero();
  double radius_m = 0.01;
  Vec3f colour = Vec3f(0.9f, 0.3f, 0.2f);
  /// Edges only (e.g. bounding-sphere display) instead of a filled, lit sphere.
  bool wireframe = false;
};

/// A rounded rod from `a_world` to `b_world` (a phalanx, a robot link, a master arm's segment),
/// lit: a cylinder of `radius_m` with a sphere of the same radius at each end. Drawn filled in
/// every display mode, like the spheres.
struct RenderCapsule {
  Vec3 a_world = Vec3::Zero();
  Vec3 b_world = Vec3::Zero();
  double radius_m = 0.01;
  Vec3f colour = Vec3f(0.8f, 0.8f, 0.8f);
};

/// A straight line from `a_world` to `b_world`, unlit, drawn RenderStyle::line_width_px wide.
struct RenderSegment {
  Vec3 a_world = Vec3::Zero();
  Vec3 b_world = Vec3::Zero();
  Vec3f colour = Vec3f(1.0f, 1.0f, 0.0f);
};

/// An 'x' on the floor plane directly below (or above) `point_world`: two crossed bars, each
/// 2·arm_m long and width_m wide, in the floor plane.
struct ShadowMark {
  Vec3 point_world = Vec3::Zero();
  double arm_m = 0.01;
  double width_m = 0.002;
  Vec3f colour = Vec3f(0.1f, 0.1f, 0.1f);
};

/// A checkerboard square in the plane z = height_m, unlit.
struct RenderFloor {
  bool visible = true;
  double height_m = 0.0;
  /// Centre (x, y) of the square and its half side, metres.
  double centre_x_m = 0.0;
  double centre_y_m = 0.0;
  double half_extent_m = 0.5;
  /// Checker cell side, metres.
  double cell_m = 0.05;
  Vec3f colour_a = Vec3f(0.72f, 0.72f, 0.74f);
  Vec3f colour_b = Vec3f(0.62f, 0.62f, 0.65f);
};

/// The knee paper's room (001 §3.1: the hand, the knee and the room walls): two walls standing on
/// the floor's far edges as seen from the camera (the corner behind the scene wherever the view
/// turns), `height_m` tall, unlit, one a little darker than the other. Needs the floor.
struct RenderRoom {
  bool visible = false;
  double height_m = 0.5;
  Vec3f colour = Vec3f(0.78f, 0.76f, 0.70f);
};

/// Which frame a light's direction is given in: fixed in the world, or moving with the camera
/// (a "headlight" rig: the lit side stays the side you look at while orbiting).
enum class LightFrame { kWorld, kCamera };

struct DirectionalLight {
  /// Unit vector from the surface towards the light, in `frame` (camera frame: x right, y up,
  /// z towards the viewer).
  Vec3 direction_to_light = Vec3::UnitZ();
  Vec3f colour = Vec3f(1.0f, 1.0f, 1.0f);
  LightFrame frame = LightFrame::kCamera;
};

struct Lighting {
  /// At most kMaxLights are used. Default: a key light from upper left-front, a dimmer fill
  /// from lower right, both camera-fixed.
  std::vector<DirectionalLight> lights = {
      {Vec3(-0.4, 0.6, 0.7).normalized(), Vec3f(0.75f, 0.75f, 0.72f), LightFrame::kCamera},
      {Vec3(0.6, -0.3, 0.5).normalized(), Vec3f(0.3f, 0.3f, 0.33f), LightFrame::kCamera}};
  Vec3f ambient = Vec3f(0.18f, 0.18f, 0.2f);
  /// Blinn-Phong specular weight and exponent (white highlights).
  float specular = 0.2f;
  float shininess = 32.0f;

  static constexpr int kMaxLights = 4;
};

struct RenderStyle {
  DisplayMode display_mode = DisplayMode::kFaces;
  ColourMode colour_mode = ColourMode::kVertexColours;
  Vec3f background = Vec3f(0.16f, 0.17f, 0.2f);
  /// Vertex size in DisplayMode::kPoints.
  float point_size_px = 3.0f;
  /// Width of segments and of mesh edges in kLines (clamped to what the driver supports).
  float line_width_px = 1.0f;
  /// Draw far meshes at a coarser level of detail (the viewer turns it on; snapshots and the
  /// reference pictures draw full meshes: at their sizes Gouraud shading over coarse triangles
  /// shows) (RenderMesh::lod_levels), one whose error
  /// looks no larger than `lod_max_error_px` on screen (its reported error, a bound about twice
  /// the typical true one: 2 px looks the same as the full mesh on the VHF knee); off: always the
  /// full meshes.
  bool level_of_detail = false;
  double lod_max_error_px = 2.0;
};

class RenderScene {
 public:
  /// Registers a mesh (copied) and returns its id (ids are 0, 1, 2, … in order of adding).
  /// Vertex normals are computed here if `mesh` has none.
  MeshId add_mesh(const TriangleMesh& mesh_M, const Vec3f& colour,
                  const Iso3& X_world_mesh = Iso3::Identity());
  MeshId add_mesh(std::span<const Vec3> positions_M, std::span<const TriangleIndices> triangles,
                  const Vec3f& colour, const Iso3& X_world_mesh = Iso3::Identity());
  /// New positions for a deforming mesh (same vertex count and order); recomputes its vertex
  /// normals. Allocation-free after the first call. Throws hapsim::Error on a size mismatch.
  void update_positions(MeshId id, std::span<const Vec3> positions_M);
  /// Drops a mesh's coarser levels (it is always drawn in full): for a mesh whose detail comes
  /// from its deformation, not its rest shape (a sheet: flat at rest, its levels lose the dent).
  void drop_lod_levels(MeshId id);
  /// Per-vertex colours (one per vertex), or an empty span to go back to the mesh colour.
  void set_vertex_colours(MeshId id, std::span<const Vec3f> colours);

  [[nodiscard]] RenderMesh& mesh(MeshId id);
  [[nodiscard]] const RenderMesh& mesh(MeshId id) const;
  [[nodiscard]] std::size_t mesh_count() const { return meshes_.size(); }

  /// World bounds of the visible meshes, spheres and capsules (for OrbitCamera::frame); empty if
  /// none.
  [[nodiscard]] Box3 bounds_world() const;

  /// Per-frame content: cleared and refilled by the app (vectors keep their capacity).
  std::vector<RenderSphere> spheres;
  std::vector<RenderCapsule> capsules;
  std::vector<RenderSegment> segments;
  std::vector<ShadowMark> shadow_marks;

  RenderFloor floor;
  RenderRoom room;
  Lighting lighting;
  RenderStyle style;

 private:
  RenderMesh& checked(MeshId id, const char* where);
  std::vector<RenderMesh> meshes_;
};

}  // namespace hapsim
