// A teleoperation World as the renderer sees it (000): the slave arm (its URDF collision meshes
// posed at their chain frames, or — for a chain without meshes, like the procedural Motoman — one
// box per link between consecutive joint origins with a sphere at each joint), the parallel gripper
// (a palm and two pads), the ball, the virtual sheet (its surface updated from the heights), a
// floor at the environment's floor, an 'x' shadow mark on the floor under the gripper's tool point,
// and the master arm drawn small as lines beside the scene. Updated each frame from a
// TeleopSnapshot (the viewer, off the haptic thread) or straight from the world (on the thread that
// steps it).
#pragma once

#include "hapsim/render/render_scene.h"
#include "hapsim/runtime/teleop_snapshot.h"

#include <array>
#include <vector>

namespace hapsim {

/// Colours (RGB in [0, 1]): a Motoman-like orange robot, a red ball, a light blue sheet.
struct TeleopSceneColours {
  Vec3f robot = Vec3f(0.96f, 0.60f, 0.10f);
  Vec3f joint = Vec3f(0.22f, 0.22f, 0.25f);
  Vec3f gripper = Vec3f(0.55f, 0.57f, 0.60f);
  Vec3f pad = Vec3f(0.30f, 0.32f, 0.35f);
  /// The pads while they hold the ball.
  Vec3f pad_holding = Vec3f(0.25f, 0.70f, 0.30f);
  Vec3f ball = Vec3f(0.86f, 0.12f, 0.10f);
  Vec3f sheet = Vec3f(0.55f, 0.75f, 0.95f);
  Vec3f master = Vec3f(0.35f, 0.85f, 0.95f);
  Vec3f shadow = Vec3f(0.10f, 0.10f, 0.12f);
};

struct TeleopSceneOptions {
  /// Draw the master arm as lines beside the scene (its base on the floor, off the slave's −y
  /// side), at this fraction of its real size.
  bool show_master = true;
  double master_display_scale = 0.5;
  /// Spheres at the slave's joints (only for a chain drawn as boxes).
  bool show_joints = true;
  TeleopSceneColours colours;
};

class TeleopScene {
 public:
  /// Builds the meshes from the world (its slave chain, gripper, ball and sheet) and shows the
  /// world's current state. `world` must outlive the scene; only its immutable parts (chain,
  /// parameters) are read after construction, so update() may run on another thread than the
  /// one stepping the world.
  explicit TeleopScene(const World& world, TeleopSceneOptions options = {});
  TeleopScene(const TeleopScene&) = delete;
  TeleopScene& operator=(const TeleopScene&) = delete;
  TeleopScene(TeleopScene&&) = delete;
  TeleopScene& operator=(TeleopScene&&) = delete;
  ~TeleopScene() = default;

  /// From a snapshot (made for the same world): poses the links, pads, ball and master; the
  /// sheet is re-uploaded only when its heights changed.
  void update(const TeleopSnapshot& snapshot);
  /// From the world itself (only on the thread that steps it, while it is not stepping).
  void update_from_world(const World& world);

  void set_options(const TeleopSceneOptions& options);
  [[nodiscard]] const TeleopSceneOptions& options() const { return options_; }

  [[nodiscard]] RenderScene& scene() { return scene_; }
  [[nodiscard]] const RenderScene& scene() const { return scene_; }
  /// Bounds of the scene as built (slave at its start, ball, sheet, master), for framing.
  [[nodiscard]] const Box3& rest_bounds_world() const { return rest_bounds_world_; }

  /// The slave's link meshes (URDF link meshes, or boxes base → joint 0 → … → tip, skipping
  /// links of zero length), in chain order.
  [[nodiscard]] const std::vector<MeshId>& link_meshes() const { return link_mesh_ids_; }
  /// Pad i (0: tool +y side, 1: −y side, as the rig places its pad bodies): a box of the
  /// gripper's pad half extents whose pose X_world_mesh is the pad centre with the tool's
  /// orientation.
  [[nodiscard]] MeshId pad_mesh(int pad) const { return pads_.at(static_cast<std::size_t>(pad)); }
  [[nodiscard]] MeshId sheet_mesh() const { return sheet_; }
  /// Where the master's base is drawn and at what scale: p_world = origin + scale · p_master.
  [[nodiscard]] const Vec3& master_display_origin_world() const { return master_origin_world_; }

 private:
  struct Link {
    MeshId mesh = 0;
    int frame = -1;  // −1: base (the world); i: joint i's frame after its motion
    Iso3 X_frame_mesh = Iso3::Identity();
  };
  void build_slave();
  void build_gripper();
  void pose_from(const TeleopSnapshot& s);
  void add_master_lines(const TeleopSnapshot& s);

  const World& world_;
  TeleopSceneOptions options_;
  RenderScene scene_;
  std::vector<Link> links_;
  std::vector<MeshId> link_mesh_ids_;
  std::vector<double> joint_radius_m_;  // per joint; empty: no joint spheres (URDF meshes)
  std::vector<MeshId> gripper_body_;    // palm and stem, posed by the tool pose
  std::array<MeshId, 2> pads_{};
  MeshId sheet_ = 0;
  std::vector<Vec3> sheet_positions_;  // sheet frame; x, y fixed, z from the heights
  std::vector<double> uploaded_heights_m_;
  std::vector<Iso3> frames_;  // scratch: the slave's joint frames
  TeleopSnapshot scratch_;    // update_from_world fills this
  Vec3 master_origin_world_ = Vec3::Zero();
  Box3 rest_bounds_world_;
};

}  // namespace hapsim
