// A slave robot drawn from its model (architecture.md#viewer): a URDF chain's visual meshes with
// their materials' colours (the GP7's CAD shells, not its coarser collision hulls), each at its
// chain frame for the joints shown; a chain without visuals (the procedural Motoman) as rounded
// links between consecutive joint origins, tapering to the flange, with a drum along each joint's
// axis and a base plate. A URDF chain with collision meshes but no visuals is drawn from its
// collision meshes (the world's link bodies, which the figure then leaves shown).
#pragma once

#include "hapsim/kinematics/serial_chain.h"
#include "hapsim/render/render_scene.h"

#include <span>
#include <string>
#include <vector>

namespace hapsim {

struct SlaveLook {
  /// Links without a material colour (Yaskawa's blue).
  Vec3f link = Vec3f(0.13f, 0.15f, 0.75f);
  /// Joint drums and the base plate.
  Vec3f joint = Vec3f(0.30f, 0.31f, 0.34f);
};

class SlaveFigure {
 public:
  /// Registers the chain's visual meshes in `scene` (mesh files loaded now). A visual that cannot
  /// be loaded is left out and said in warnings(); when none is left the chain is drawn with
  /// rounded links.
  SlaveFigure(const SerialChain& chain, RenderScene& scene, const SlaveLook& look = {});

  /// Whether the chain is drawn from its URDF visual meshes.
  [[nodiscard]] bool uses_visual_meshes() const { return !visuals_.empty(); }
  /// Whether the figure draws the links itself (visual meshes or rounded links), so the world's
  /// link bodies (collision shapes) are to be hidden.
  [[nodiscard]] bool draws_links() const { return !visuals_.empty() || rounded_; }
  [[nodiscard]] const std::vector<std::string>& warnings() const { return warnings_; }
  [[nodiscard]] std::size_t visual_triangle_count() const { return visual_triangles_; }

  /// Places the visual meshes at `frames` (the chain's joint frames, world = chain base, as
  /// SerialChain::frames gives them with `tip_world`), or appends the rounded links' capsules
  /// (with the joints' drums when `joints`).
  void update(std::span<const Iso3> frames, const Iso3& tip_world, RenderScene& scene,
              bool joints = true) const;

 private:
  struct Visual {
    MeshId mesh = 0;
    int frame = -1;
    Iso3 X_frame_mesh = Iso3::Identity();
  };
  const SerialChain& chain_;
  SlaveLook look_;
  std::vector<Visual> visuals_;
  std::vector<std::string> warnings_;
  std::size_t visual_triangles_ = 0;
  bool rounded_ = false;               // no visuals, no collision meshes: rounded links
  std::vector<double> link_radius_m_;  // per link 0..dof (rounded links)
};

}  // namespace hapsim
