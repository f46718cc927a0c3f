#include "hapsim/render/slave_figure.h"

#include "hapsim/core/error.h"
#include "hapsim/geometry/mesh_io.h"
#include "hapsim/render/creased_normals.h"

#include <algorithm>

namespace hapsim {

namespace {

// Edges of a CAD shell sharper than this stay sharp.
constexpr double kCreaseRad = 0.6;

// Origin of frame k (k = dof: the tip) in frame k − 1.
Vec3 link_offset(const SerialChain& chain, int k) {
  return k < chain.dof() ? chain.joints()[static_cast<std::size_t>(k)].X_parent_joint.translation()
                         : chain.X_last_tip().translation();
}

}  // namespace

SlaveFigure::SlaveFigure(const SerialChain& chain, RenderScene& scene, const SlaveLook& look)
    : chain_(chain), look_(look) {
  for (const ChainLinkVisual& v : chain.link_visuals()) {
    TriangleMesh mesh;
    if (!v.mesh_file.empty()) {
      try {
        MeshLoadOptions o;
        o.compute_normals = false;
        mesh = load_mesh(v.mesh_file, o);
      } catch (const Error& e) {
        warnings_.push_back("link '" + v.link + "': visual mesh not drawn (" + e.where() + ": " +
                            e.detail() + "); its collision shape stands in");
        continue;
      }
      for (Vec3& p : mesh.vertices) {
        p = p.cwiseProduct(v.mesh_scale);
      }
    } else {
      mesh = v.mesh;
    }
    if (mesh.triangles.empty()) {
      continue;
    }
    visual_triangles_ += mesh.triangles.size();
    const MeshId id =
        scene.add_mesh(with_creased_normals(mesh, kCreaseRad), v.has_colour ? v.colour : look.link);
    scene.mesh(id).name = "slave/" + v.link;
    visuals_.push_back({id, v.frame, v.X_frame_mesh});
  }
  rounded_ =
      visuals_.empty() && std::none_of(chain.link_geometry().begin(), chain.link_geometry().end(),
                                       [](const ChainLinkGeometry& g) { return !g.mesh.empty(); });
  // Rounded links: thickest at the base, tapering to the flange, in proportion to the arm.
  double total_m = 0.0;
  for (int k = 0; k <= chain.dof(); ++k) {
    total_m += link_offset(chain, k).norm();
  }
  const double scale = std::max(total_m, 0.1);
  for (int k = 0; k <= chain.dof(); ++k) {
    const double u = chain.dof() > 0 ? static_cast<double>(k) / chain.dof() : 0.0;
    link_radius_m_.push_back(scale * (0.033 - 0.014 * u));
  }
}

void SlaveFigure::update(std::span<const Iso3> frames, const Iso3& tip_world, RenderScene& scene,
                         bool joints) const {
  const auto frame_pose = [&](int f) {
    return f < 0 ? Iso3::Identity() : frames[static_cast<std::size_t>(f)];
  };
  if (!visuals_.empty()) {
    for (const Visual& v : visuals_) {
      RenderMesh& m = scene.mesh(v.mesh);
      m.X_world_mesh = frame_pose(v.frame) * v.X_frame_mesh;
    }
    return;
  }
  if (!rounded_) {
    return;
  }
  const int n = chain_.dof();
  // A base plate on the mount, then each link from one joint origin to the next.
  const double r0 = link_radius_m_.front();
  scene.capsules.push_back({Vec3::Zero(), Vec3(0.0, 0.0, 0.25 * r0), 1.7 * r0, look_.joint});
  Vec3 from = Vec3::Zero();
  for (int k = 0; k <= n; ++k) {
    const Vec3 to =
        k < n ? frames[static_cast<std::size_t>(k)].translation() : tip_world.translation();
    if ((to - from).norm() > 1e-6) {
      scene.capsules.push_back({from, to, link_radius_m_[static_cast<std::size_t>(k)], look_.link});
    }
    from = to;
  }
  // A drum along each joint's axis, wider than the links it joins.
  for (int k = 0; joints && k < n; ++k) {
    const auto kk = static_cast<std::size_t>(k);
    const double r = 1.15 * std::max(link_radius_m_[kk], link_radius_m_[kk + 1]);
    const Vec3 axis_world = frames[kk].linear() * chain_.joints()[kk].axis;
    const Vec3 c = frames[kk].translation();
    scene.capsules.push_back({c - 0.8 * r * axis_world, c + 0.8 * r * axis_world, r, look_.joint});
  }
}

}  // namespace hapsim
