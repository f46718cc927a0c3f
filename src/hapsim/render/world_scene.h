// A World as the renderer sees it (architecture.md#viewer): one mesh per segment, coloured by
// tissue (bone, cartilage, ligament, muscle, skin) or per segment / per vertex group (the knee
// paper's Fig. 3), the tools as spheres with their god-object proxies and force arrows, an 'x'
// shadow mark on the floor under each tool, and optionally the sphere tree's spheres at one level.
// Updated each frame from a WorldSnapshot (the viewer, off the haptic thread) or straight from the
// World (a headless run, on the thread that steps it).
#pragma once

#include "hapsim/render/render_scene.h"
#include "hapsim/runtime/world_snapshot.h"

#include <memory>
#include <vector>

namespace hapsim {

enum class SegmentColouring {
  kTissue,    ///< by material: bone ivory, muscle red, ligament pale yellow, skin skin-tone …
  kSegments,  ///< each segment its own palette colour
  kGroups,    ///< each knee-method vertex group its own colour (computed on first use)
};

struct WorldSceneOptions {
  SegmentColouring colouring = SegmentColouring::kTissue;
  /// Sphere-tree level to show as wireframe spheres (root = 0), −1: none.
  int sphere_tree_level = -1;
  bool show_proxies = true;
  bool show_force_arrows = true;
  /// Force arrow length per newton, metres.
  double arrow_m_per_n = 0.005;
};

class WorldScene {
 public:
  /// Builds the render meshes from the world's description (rest shapes; call update_* to show
  /// the current state).
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

  void set_options(const WorldSceneOptions& options);
  [[nodiscard]] const WorldSceneOptions& options() const { return options_; }
  /// Shows or hides one segment (flat index, World::flat_segment).
  void set_segment_visible(std::size_t flat_segment, bool visible);
  [[nodiscard]] bool segment_visible(std::size_t flat_segment) const;
  [[nodiscard]] std::size_t segment_count() const { return segments_.size(); }
  [[nodiscard]] const std::string& segment_label(std::size_t flat_segment) const;

  [[nodiscard]] RenderScene& scene() { return scene_; }
  [[nodiscard]] const RenderScene& scene() const { return scene_; }
  /// Bounds of the bodies at rest (for framing the camera).
  [[nodiscard]] const Box3& rest_bounds_world() const { return rest_bounds_world_; }

  /// The colour of a material by its name (what kTissue uses), for legends.
  [[nodiscard]] static Vec3f tissue_colour(std::string_view material_name, int material_index);

 private:
  struct Segment;
  void apply_colouring();
  void rebuild_overlays(const std::vector<ToolState>& tools, const std::vector<double>& force_n);

  const World& world_;
  WorldSceneOptions options_;
  RenderScene scene_;
  std::vector<std::unique_ptr<Segment>> segments_;  // flat
  std::vector<Vec3> scratch_positions_;
  std::vector<ToolState> tools_;
  std::vector<double> tool_force_n_;
  std::vector<Iso3> body_poses_;  // where each body is drawn (dynamic bodies move)
  Box3 rest_bounds_world_;
};

}  // namespace hapsim
