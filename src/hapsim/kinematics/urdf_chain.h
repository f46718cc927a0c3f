// Serial chains from URDF files, read through urdfdom: revolute, continuous and prismatic joints
// become chain joints, fixed joints fold into the neighbouring transforms, and each link's
// collision geometry (mesh files through Assimp, or box / sphere / cylinder) is attached to its
// frame. The Motoman GP7 of ROS-Industrial loads this way.
#pragma once

#include "hapsim/kinematics/serial_chain.h"

#include <filesystem>
#include <string>
#include <string_view>

namespace hapsim {

struct UrdfChainOptions {
  /// First link of the chain; empty: the URDF's root link.
  std::string base_link;
  /// Last link; empty: the link with the most movable joints between it and the base (one such
  /// link, or an error listing the candidates).
  std::string tip_link;
  /// Load the links' collision geometry (mesh paths resolve against the URDF's folder).
  bool load_collision_meshes = true;
};

/// Throws hapsim::Error naming the file (and the joint or link) when the file is missing, is not
/// a URDF urdfdom can parse, the links are not connected, a joint in the chain is floating or
/// planar, or a collision mesh cannot be loaded.
[[nodiscard]] SerialChain load_urdf_chain(const std::filesystem::path& file,
                                          const UrdfChainOptions& options = {});

/// The same from URDF text; `name` stands for the file in messages, `folder` anchors mesh paths.
[[nodiscard]] SerialChain parse_urdf_chain(std::string_view urdf_xml, std::string_view name,
                                           const std::filesystem::path& folder,
                                           const UrdfChainOptions& options = {});

}  // namespace hapsim
