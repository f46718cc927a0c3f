// A serial manipulator: a base frame, a list of 1-DOF joints (revolute or prismatic), a tip frame.
// Forward kinematics chains homogeneous transforms: frame_i = frame_{i-1} · X_parent_joint_i ·
// motion_i(q_i), tip = frame_{n-1} · X_last_tip. Built from a Denavit–Hartenberg table
// (dh_chain.h) or a URDF file (urdf_chain.h). Every query is allocation-free (fixed-capacity
// Eigen types), so a slave's FK, Jacobian and IK can run on the haptic path.
#pragma once

#include "hapsim/core/types.h"
#include "hapsim/geometry/triangle_mesh.h"

#include <Eigen/Core>

#include <span>
#include <string>
#include <vector>

namespace hapsim {

/// Most movable joints a chain may have (a 7-DOF arm plus a gripper fits with room to spare).
inline constexpr int kMaxChainJoints = 12;

enum class JointType { kRevolute, kPrismatic };

struct ChainJoint {
  std::string name;
  JointType type = JointType::kRevolute;
  /// The joint frame in the previous joint's (moved) frame, or in the base frame for the first.
  Iso3 X_parent_joint = Iso3::Identity();
  /// Unit axis in the joint frame: rotation axis (right hand) or translation direction.
  Vec3 axis = Vec3::UnitZ();
  /// Position limits, rad or m (−inf/+inf: unlimited, e.g. a URDF "continuous" joint).
  double lower = -kInf;
  double upper = kInf;
  /// Speed limit, rad/s or m/s (inf: none).
  double max_velocity = kInf;
  /// The link this joint moves (named for meshes and for --tip).
  std::string child_link;
};

/// A link's collision mesh, attached to one of the chain's frames.
struct ChainLinkGeometry {
  std::string link;
  /// −1: the base frame; i: the frame of joint i (after its motion).
  int frame = -1;
  /// The mesh's frame in that chain frame (fixed joints and the collision origin folded in).
  Iso3 X_frame_mesh = Iso3::Identity();
  TriangleMesh mesh;  // metres
};

/// A link's visual shape (URDF <visual>), for display only: a mesh file, loaded by whoever draws
/// it (the collision meshes are what the world uses), or a primitive already tessellated, with
/// the URDF material's colour.
struct ChainLinkVisual {
  std::string link;
  /// −1: the base frame; i: the frame of joint i (after its motion).
  int frame = -1;
  /// The visual's frame in that chain frame (fixed joints and the visual origin folded in).
  Iso3 X_frame_mesh = Iso3::Identity();
  /// Absolute path of the mesh file and its scale; empty for a primitive (then `mesh`).
  std::string mesh_file;
  Vec3 mesh_scale = Vec3::Ones();
  TriangleMesh mesh;
  /// RGB of the visual's material, when it has one.
  bool has_colour = false;
  Vec3f colour = Vec3f(0.7f, 0.7f, 0.7f);
};

using ChainVector = Eigen::Matrix<double, Eigen::Dynamic, 1, 0, kMaxChainJoints, 1>;
/// Geometric Jacobian in the base frame at the tip: rows 0–2 linear velocity of the tip origin,
/// rows 3–5 angular velocity.
using ChainJacobian = Eigen::Matrix<double, 6, Eigen::Dynamic, 0, 6, kMaxChainJoints>;

class SerialChain {
 public:
  /// Throws hapsim::Error naming the joint on a non-finite transform, a zero axis, lower >
  /// upper, a negative speed limit, or more than kMaxChainJoints joints. Axes are normalised.
  SerialChain(std::string base_link, std::vector<ChainJoint> joints, Iso3 X_last_tip,
              std::string tip_link);

  [[nodiscard]] int dof() const { return static_cast<int>(joints_.size()); }
  [[nodiscard]] const std::vector<ChainJoint>& joints() const { return joints_; }
  [[nodiscard]] const std::string& base_link() const { return base_link_; }
  [[nodiscard]] const std::string& tip_link() const { return tip_link_; }
  [[nodiscard]] const Iso3& X_last_tip() const { return X_last_tip_; }

  /// Tip pose in the base frame. `q` has dof() values. haptic path
  [[nodiscard]] Iso3 forward(std::span<const double> q) const noexcept;
  /// Frame of every joint after its motion (frames.size() ≥ dof()), and the tip pose. haptic path
  Iso3 frames(std::span<const double> q, std::span<Iso3> frames) const noexcept;
  /// Geometric Jacobian at the tip (see ChainJacobian). haptic path
  [[nodiscard]] ChainJacobian jacobian(std::span<const double> q) const noexcept;

  /// Whether every q_i lies in [lower_i, upper_i] (and is finite).
  [[nodiscard]] bool within_limits(std::span<const double> q) const noexcept;
  /// Clamps every q_i into its limits (a NaN becomes the limits' midpoint, or 0). haptic path
  void clamp_to_limits(std::span<double> q) const noexcept;

  /// Collision meshes of the links, when loaded (URDF); empty otherwise.
  [[nodiscard]] const std::vector<ChainLinkGeometry>& link_geometry() const { return links_; }
  void set_link_geometry(std::vector<ChainLinkGeometry> links);
  /// Visual shapes of the links (URDF), for display; empty when the chain has none.
  [[nodiscard]] const std::vector<ChainLinkVisual>& link_visuals() const { return visuals_; }
  void set_link_visuals(std::vector<ChainLinkVisual> visuals) { visuals_ = std::move(visuals); }

  /// Index of the joint whose child is `link`, −1 for the base link, −2 when not in the chain.
  [[nodiscard]] int frame_of_link(const std::string& link) const;

 private:
  std::string base_link_;
  std::vector<ChainJoint> joints_;
  Iso3 X_last_tip_;
  std::string tip_link_;
  std::vector<ChainLinkGeometry> links_;
  std::vector<ChainLinkVisual> visuals_;
};

/// The motion of one joint at position q: a rotation q about the axis or a translation q along it.
[[nodiscard]] Iso3 joint_motion(const ChainJoint& joint, double q) noexcept;

}  // namespace hapsim
