// A World as the renderer sees it (architecture.md#viewer), the one render adapter: one mesh per
// segment where its body is now, coloured by tissue (bone, cartilage, ligament, muscle, skin) or
// per segment / per vertex group (the knee paper's Fig. 3), deformed surfaces and sheets (their
// live dent) re-uploaded when they change, the tools as spheres with their god-object proxies and
// force arrows, an 'x' shadow mark on the floor under each tool, and optionally the sphere tree's
// spheres at one level or the knee method's spheres of influence and a contact's three vertices. A
// teleoperation rig's bodies are drawn as bodies too (the slave's links robot orange, the palm and
// stem grey, the pads grey or green while they hold, the ball red, the sheet light blue, darker
// where it is dented; its floor as the checked floor); what only a rig has is drawn from the
// snapshot's teleop part: the master arm small as lines beside the scene, spheres at the joints of
// a slave drawn as boxes, the shadow mark under the gripper. Updated each frame from a
// WorldSnapshot (the viewer, off the haptic thread) or straight from the World (a headless run, on
// the thread that steps it).
#pragma once

#include "hapsim/render/render_scene.h"
#include "hapsim/runtime/world_snapshot.h"

#include <memory>
#include <optional>
#include <span>
#include <string>
#include <vector>

namespace hapsim {

enum class SegmentColouring {
  kTissue,    ///< by material: bone ivory, muscle red, ligament pale yellow, skin skin-tone …
  kSegments,  ///< each segment its own palette colour
  kGroups,    ///< each knee-method vertex group its own colour (computed on first use)
  /// FEM bodies by their von Mises stress (their tissue colour at 0, through yellow to red at
  /// the largest stress on them this frame: fem_stress_full_scale_pa()); the rest by tissue.
  kStress,
};

struct WorldSceneOptions {
  SegmentColouring colouring = SegmentColouring::kTissue;
  /// Sphere-tree level to show as wireframe spheres (root = 0), −1: none.
  int sphere_tree_level = -1;
  bool show_proxies = true;
  bool show_force_arrows = true;
  /// A tool's force at which it is drawn full red, N; 0: the scene's largest contact force
  /// (force_scale.h).
  double force_full_scale_n = 0.0;
  /// The knee paper's room: walls on the floor's far edges, a little taller than the scene.
  bool show_room = false;
  /// Force arrow length per newton, metres.
  double arrow_m_per_n = 0.005;
  /// A rig's master arm drawn as lines beside the scene (its base on the floor, off the slave's
  /// −y side), at this fraction of its real size.
  bool show_master = true;
  double master_display_scale = 0.5;
  /// Drums along a rig slave's joint axes (a chain drawn with rounded links).
  bool show_joints = true;
  /// The knee method's overlays (the knee paper's Fig. 3), on the visible segments: each vertex
  /// group's sphere of influence as three great circles in a dark shade of the group's colour ...
  bool show_influence_spheres = false;
  /// ... and, for each tool touching something within a centimetre of a visible segment (the
  /// paper's "point of possible contact"; the nearest such segment), the three vertices closest in
  /// angle to the tool about its group's centroid, whose plane the method tests, as dark spheres
  /// joined by the triangle they span.
  bool show_contact_vertices = false;
};

/// Colours of a rig's parts (RGB in [0, 1]): a Motoman in Yaskawa's blue, a red ball.
struct RigColours {
  Vec3f robot = Vec3f(0.13f, 0.15f, 0.75f);
  Vec3f joint = Vec3f(0.30f, 0.31f, 0.34f);
  Vec3f gripper = Vec3f(0.55f, 0.57f, 0.60f);
  Vec3f pad = Vec3f(0.30f, 0.32f, 0.35f);
  /// The pads while they hold the ball.
  Vec3f pad_holding = Vec3f(0.25f, 0.70f, 0.30f);
  Vec3f ball = Vec3f(0.86f, 0.12f, 0.10f);
  Vec3f sheet = Vec3f(0.55f, 0.75f, 0.95f);
  Vec3f master = Vec3f(0.35f, 0.80f, 0.90f);
  Vec3f shadow = Vec3f(0.10f, 0.10f, 0.12f);
};

class KneeIndex;
class SlaveFigure;

class WorldScene {
 public:
  /// Builds the render meshes from the world's description (rest shapes, at the bodies' current
  /// poses; call update_* to show the current state).
  explicit WorldScene(const World& world, WorldSceneOptions options = {});
  ~WorldScene();
  WorldScene(const WorldScene&) = delete;
  WorldScene& operator=(const WorldScene&) = delete;
  WorldScene(WorldScene&&) = delete;
  WorldScene& operator=(WorldScene&&) = delete;

  /// From a snapshot: deformed segments (and sheets) re-uploaded only when their version
  /// changed; every segment drawn where its body is now.
  void update(const WorldSnapshot& snapshot);
  /// From the world itself (only on the thread that steps it, while it is not stepping).
  void update_from_world(const World& world);
  /// FEM bodies' surfaces as their FEM side last published them (world/fem_coupling.h; the one
  /// display thread): in a live session they move on the FEM thread, not in the snapshots.
  void update_fem_surfaces(World& world);
  /// kStress: the von Mises stress drawn red on the FEM bodies in the last frame (Pa; 0 when
  /// there is none).
  [[nodiscard]] double fem_stress_full_scale_pa() const { return fem_stress_full_scale_pa_; }

  void set_options(const WorldSceneOptions& options);
  [[nodiscard]] const WorldSceneOptions& options() const { return options_; }
  /// Shows or hides one segment (flat index, World::flat_segment).
  void set_segment_visible(std::size_t flat_segment, bool visible);
  [[nodiscard]] bool segment_visible(std::size_t flat_segment) const;
  [[nodiscard]] std::size_t segment_count() const { return segments_.size(); }
  [[nodiscard]] const std::string& segment_label(std::size_t flat_segment) const;

  [[nodiscard]] RenderScene& scene() { return scene_; }
  [[nodiscard]] const RenderScene& scene() const { return scene_; }
  /// Bounds of the bodies where the description starts them (for framing the camera); with a
  /// rig, its master drawn beside.
  [[nodiscard]] const Box3& rest_bounds_world() const { return rest_bounds_world_; }
  /// The render mesh of a segment (flat index).
  [[nodiscard]] MeshId segment_mesh(std::size_t flat_segment) const;
  /// With a rig: where its master's base is drawn (p_world = origin + scale · p_master).
  [[nodiscard]] const Vec3& master_display_origin_world() const { return master_origin_world_; }
  /// With a rig: how its slave is drawn (visual meshes, rounded links or collision meshes).
  [[nodiscard]] const SlaveFigure* slave_figure() const { return slave_figure_.get(); }
  /// What the scene could not draw as asked (a URDF visual mesh that did not load), once each.
  [[nodiscard]] const std::vector<std::string>& warnings() const { return warnings_; }

  /// The colour of a material by its name (what kTissue uses), for legends.
  [[nodiscard]] static Vec3f tissue_colour(std::string_view material_name, int material_index);

 private:
  struct Segment;
  void build_rig();
  void show_slave_link_bodies(bool visible);
  void apply_colouring();
  void shade_dent(Segment& seg);
  /// kStress: a FEM segment's vertices coloured by their von Mises stress.
  void shade_stress(Segment& seg, std::span<const float> von_mises_pa);
  void add_sheet_grid(const Segment& seg);
  [[nodiscard]] bool hand_agrees_with_tools() const;
  /// The segment's knee-method index on its rest mesh, built on first use (its groups colour the
  /// segment and give the overlays).
  const KneeIndex& knee_index(Segment& seg);
  [[nodiscard]] bool knee_overlays_apply(const Segment& seg) const;
  void add_knee_overlays();
  void add_circles(const Vec3& centre_world, double radius_m, const Vec3f& colour);
  void rebuild_overlays(const std::vector<ToolState>& tools, const std::vector<double>& force_n);
  void add_rig_overlays();
  void add_master(const TeleopSnapshot& s);

  const World& world_;
  WorldSceneOptions options_;
  RigColours rig_colours_;
  RenderScene scene_;
  std::vector<std::unique_ptr<Segment>> segments_;  // flat
  std::vector<Vec3> scratch_positions_;
  std::vector<Vec3f> scratch_colours_;
  double fem_stress_full_scale_pa_ = 0.0;
  std::vector<ToolState> tools_;
  std::vector<double> tool_force_n_;
  int next_group_colour_ = 0;     // palette index of the next segment's first group
  std::vector<Iso3> body_poses_;  // where each body is drawn (dynamic bodies move)
  Box3 rest_bounds_world_;
  // A glove world's hand, as the last update saw it.
  bool has_hand_ = false;
  GloveReading hand_;
  // A rig's part: its latest state, how the slave is drawn, the slave's joint frames (scratch),
  // where the master is drawn.
  std::optional<TeleopSnapshot> rig_;
  std::unique_ptr<SlaveFigure> slave_figure_;
  std::vector<std::string> warnings_;
  std::vector<Iso3> frames_;
  Vec3 master_origin_world_ = Vec3::Zero();
};

}  // namespace hapsim
