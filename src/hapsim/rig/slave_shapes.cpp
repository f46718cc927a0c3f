#include "hapsim/rig/slave_shapes.h"

#include "hapsim/geometry/vertex_welding.h"

#include <algorithm>
#include <cmath>

namespace hapsim {

namespace {

// Origin of frame k (k = n: the tip) in frame k − 1.
Vec3 link_offset(const SerialChain& chain, int k) {
  return k < chain.dof() ? chain.joints()[static_cast<std::size_t>(k)].X_parent_joint.translation()
                         : chain.X_last_tip().translation();
}

// Half the side of link k's square cross-section: the base link thickest, tapering to the tip,
// in proportion to the arm's length.
double link_half_width_m(const SerialChain& chain, int k) {
  double total_m = 0.0;
  for (int j = 0; j <= chain.dof(); ++j) {
    total_m += link_offset(chain, j).norm();
  }
  const double scale = std::max(total_m, 0.1);
  const int n = chain.dof();
  const double u = n > 0 ? static_cast<double>(k) / static_cast<double>(n) : 0.0;
  return scale * (0.035 - 0.015 * u);
}

// No edge of a slave box is longer than this: slave collisions test points spread over a shape's
// surface (its sphere tree's leaves), so a long link crossing a thin table with its corners on
// both sides still has some inside it.
constexpr double kMaxBoxEdgeM = 0.02;

// A closed box with half extents `half`, each face a grid of squares no wider than kMaxBoxEdgeM.
TriangleMesh tessellated_box(const Vec3& half) {
  TriangleMesh m;
  for (int a = 0; a < 3; ++a) {
    const int u = (a + 1) % 3;
    const int v = (a + 2) % 3;
    const int nu = std::max(1, static_cast<int>(std::ceil(2.0 * half[u] / kMaxBoxEdgeM)));
    const int nv = std::max(1, static_cast<int>(std::ceil(2.0 * half[v] / kMaxBoxEdgeM)));
    for (const double side : {-1.0, 1.0}) {
      const auto base = static_cast<std::uint32_t>(m.vertices.size());
      for (int j = 0; j <= nv; ++j) {
        for (int i = 0; i <= nu; ++i) {
          Vec3 p = Vec3::Zero();
          p[a] = side * half[a];
          p[u] = half[u] * (2.0 * i / nu - 1.0);
          p[v] = half[v] * (2.0 * j / nv - 1.0);
          m.vertices.push_back(p);
        }
      }
      const auto at = [&](int i, int j) {
        return base + static_cast<std::uint32_t>(j * (nu + 1) + i);
      };
      for (int j = 0; j < nv; ++j) {
        for (int i = 0; i < nu; ++i) {
          // e_u × e_v = e_a: counter-clockwise seen from +e_a; reversed on the −e_a face.
          if (side > 0.0) {
            m.triangles.push_back({at(i, j), at(i + 1, j), at(i + 1, j + 1)});
            m.triangles.push_back({at(i, j), at(i + 1, j + 1), at(i, j + 1)});
          } else {
            m.triangles.push_back({at(i, j), at(i + 1, j + 1), at(i + 1, j)});
            m.triangles.push_back({at(i, j), at(i, j + 1), at(i + 1, j + 1)});
          }
        }
      }
    }
  }
  weld_vertices(m, 1e-9);  // the faces share their edges: one closed surface
  return m;
}

// A box of square cross-section (half side `half_width_m`) from the origin to `d`.
TriangleMesh link_box(const Vec3& d, double half_width_m) {
  const double length = d.norm();
  TriangleMesh m = tessellated_box(Vec3(half_width_m, half_width_m, 0.5 * length));
  const Quat R = Quat::FromTwoVectors(Vec3::UnitZ(), d / length);
  m.transform(Iso3(Eigen::Translation3d(0.5 * d)) * Iso3(R));
  return m;
}

bool has_meshes(const SerialChain& chain) {
  return std::any_of(chain.link_geometry().begin(), chain.link_geometry().end(),
                     [](const ChainLinkGeometry& g) { return !g.mesh.empty(); });
}

}  // namespace

std::vector<SlaveShape> slave_link_shapes(const SerialChain& chain) {
  std::vector<SlaveShape> shapes;
  if (has_meshes(chain)) {
    for (const ChainLinkGeometry& g : chain.link_geometry()) {
      if (!g.mesh.empty()) {
        shapes.push_back({g.link, g.frame, g.X_frame_mesh, g.mesh});
      }
    }
    return shapes;
  }
  for (int k = 0; k <= chain.dof(); ++k) {
    const Vec3 d = link_offset(chain, k);
    if (d.norm() < 1e-6) {
      continue;
    }
    shapes.push_back(
        {k == 0 ? chain.base_link() : chain.joints()[static_cast<std::size_t>(k - 1)].child_link,
         k - 1, Iso3::Identity(), link_box(d, link_half_width_m(chain, k))});
  }
  return shapes;
}

std::vector<double> slave_joint_radii_m(const SerialChain& chain) {
  std::vector<double> radii;
  if (has_meshes(chain)) {
    return radii;
  }
  for (int k = 0; k < chain.dof(); ++k) {
    radii.push_back(1.3 * std::max(link_half_width_m(chain, k), link_half_width_m(chain, k + 1)));
  }
  return radii;
}

std::vector<SlaveShape> gripper_shapes(const ParallelGripperParams& p, double max_width_m) {
  std::vector<SlaveShape> shapes;
  // A palm across the pads' travel just above them, and a stem from the flange down to it.
  const double palm_half_z = 0.25 * p.pad_half_m.z();
  const double palm_z = p.pad_depth_m - p.pad_half_m.z() - palm_half_z;
  shapes.push_back(
      {"gripper_palm", kToolFrame, Iso3(Eigen::Translation3d(0.0, 0.0, palm_z)),
       tessellated_box(
           Vec3(p.pad_half_m.x() * 1.2, 0.5 * max_width_m + 2.0 * p.pad_half_m.y(), palm_half_z))});
  const double stem_length = palm_z - palm_half_z;
  if (stem_length > 1e-4) {
    const double r = std::max(p.pad_half_m.x(), 0.01);
    shapes.push_back({"gripper_stem", kToolFrame,
                      Iso3(Eigen::Translation3d(0.0, 0.0, 0.5 * stem_length)),
                      tessellated_box(Vec3(r, r, 0.5 * stem_length))});
  }
  return shapes;
}

}  // namespace hapsim
