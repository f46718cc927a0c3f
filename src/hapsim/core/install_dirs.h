// Where an installed hapsim keeps its shipped files (scenes, configs, scripts):
// PREFIX/share/hapsim, found from where the hapsim library (or the program it is linked into)
// lives, so an installed `hapsim` needs no source tree; from the build tree, the build tree's own
// paths are used instead.
#pragma once

#include <filesystem>
#include <optional>
#include <string_view>

namespace hapsim {

/// PREFIX/share/hapsim when this code runs from an installed prefix (the folder holding the
/// library, or the program linked with it statically, is PREFIX/lib[/<multiarch>] or PREFIX/bin,
/// and PREFIX/share/hapsim/config exists); nullopt from the build tree.
std::optional<std::filesystem::path> installed_share_dir();

/// A shipped file or folder: `relative` under installed_share_dir() when installed, else
/// `build_tree_path` (the source tree's copy, which the build tree uses).
std::filesystem::path shipped_path(std::string_view relative,
                                   const std::filesystem::path& build_tree_path);

}  // namespace hapsim
