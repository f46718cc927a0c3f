#include "hapsim/core/install_dirs.h"

#include <dlfcn.h>

#include <string_view>
#include <system_error>

namespace hapsim {
namespace {

// PREFIX/share/hapsim for a binary in `dir` (PREFIX/bin, PREFIX/lib or PREFIX/lib/<multiarch>).
std::optional<std::filesystem::path> share_dir_above(const std::filesystem::path& dir) {
  std::error_code ec;
  for (const char* up : {"..", "../.."}) {
    const std::filesystem::path share = (dir / up / "share" / "hapsim").lexically_normal();
    if (std::filesystem::is_directory(share / "config", ec)) {
      return share;
    }
  }
  return std::nullopt;
}

std::optional<std::filesystem::path> find_installed_share_dir() {
  std::error_code ec;
  // The shared library holding this function (when hapsim is linked as shared libraries) ...
  Dl_info info{};
  // (inside the program itself dladdr names argv[0], which may be relative: skip it).
  if (dladdr(reinterpret_cast<void*>(&find_installed_share_dir), &info) != 0 &&
      info.dli_fname != nullptr &&
      std::string_view(info.dli_fname).find(".so") != std::string_view::npos) {
    const std::filesystem::path library = std::filesystem::canonical(info.dli_fname, ec);
    if (!ec) {
      if (auto share = share_dir_above(library.parent_path())) {
        return share;
      }
    }
  }
  // ... else the program itself (linked statically, or the installed `hapsim`).
  const std::filesystem::path program = std::filesystem::canonical("/proc/self/exe", ec);
  if (!ec) {
    return share_dir_above(program.parent_path());
  }
  return std::nullopt;
}

}  // namespace

std::optional<std::filesystem::path> installed_share_dir() {
  static const std::optional<std::filesystem::path> dir = find_installed_share_dir();
  return dir;
}

std::filesystem::path shipped_path(std::string_view relative,
                                   const std::filesystem::path& build_tree_path) {
  if (const auto share = installed_share_dir()) {
    return *share / relative;
  }
  return build_tree_path;
}

}  // namespace hapsim
