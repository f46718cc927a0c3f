// The solid shapes of a slave robot and its parallel gripper, as the world collides with them and
// the viewer draws them (one description for both): each link's URDF collision mesh at its chain
// frame, or — for a chain without meshes, like the procedural Motoman — one box per link between
// consecutive joint origins, tapering towards the tip; the gripper's palm (across the pads'
// travel, just above them) and the stem from the flange down to it, in the tool frame. Boxes are
// tessellated (no edge longer than 2 cm): slave collisions test points spread over a shape.
#pragma once

#include "hapsim/core/types.h"
#include "hapsim/geometry/triangle_mesh.h"
#include "hapsim/kinematics/serial_chain.h"
#include "hapsim/rig/parallel_gripper.h"

#include <string>
#include <vector>

namespace hapsim {

/// The chain frame a shape rides on: −1 the base (the world), i the frame of joint i after its
/// motion, kToolFrame the tool (flange, SerialChain::forward).
inline constexpr int kToolFrame = -2;

struct SlaveShape {
  std::string name;
  int frame = -1;
  /// The shape's mesh frame in its chain frame.
  Iso3 X_frame_mesh = Iso3::Identity();
  /// Closed and outward (it collides), metres, in the mesh frame.
  TriangleMesh mesh;
};

/// The links: the chain's non-empty collision meshes when it has any (URDF), else a box per link
/// from one joint origin to the next (base, joints 0..n−1, tip; the origin of joint k's frame is
/// fixed in frame k−1 for a revolute joint; a prismatic joint's link is the one at q = 0), links
/// of zero length skipped, in chain order.
[[nodiscard]] std::vector<SlaveShape> slave_link_shapes(const SerialChain& chain);

/// For a chain drawn as boxes: a radius per joint for a sphere that hides the boxes' joins
/// (empty when the chain has meshes).
[[nodiscard]] std::vector<double> slave_joint_radii_m(const SerialChain& chain);

/// The gripper's palm and (when there is room) stem, on kToolFrame.
[[nodiscard]] std::vector<SlaveShape> gripper_shapes(const ParallelGripperParams& gripper,
                                                     double max_width_m);

}  // namespace hapsim
