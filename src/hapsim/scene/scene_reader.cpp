#include "hapsim/scene/scene_reader.h"

#include "hapsim/core/data_dir.h"

#include <algorithm>
#include <cctype>
#include <optional>

namespace hapsim {

std::filesystem::path SceneReader::path(const Json& j, const std::string& ptr,
                                        const std::string& what) const {
  const std::string s = nonempty_string(j, ptr, what);
  if (s.rfind("data:", 0) == 0) {
    return data_dir(ptr) / s.substr(5);
  }
  const std::filesystem::path p(s);
  return p.is_absolute() ? p : file_.parent_path() / p;
}

std::filesystem::path SceneReader::existing_file(const Json& j, const std::string& ptr,
                                                 const std::string& what) const {
  std::filesystem::path p = path(j, ptr, what);
  std::error_code ec;  // a loop of symlinks or a name too long is said, not thrown
  if (!std::filesystem::is_regular_file(p, ec)) {
    fail(ptr, "no such file: " + p.string() + (ec ? " (" + ec.message() + ")" : std::string()));
  }
  return p;
}

std::filesystem::path SceneReader::data_dir(const std::string& ptr) const {
  if (!options_.data_dir.empty()) {
    std::error_code ec;
    if (!std::filesystem::is_directory(options_.data_dir, ec)) {
      fail(ptr, "the data folder " + options_.data_dir.string() + " does not exist");
    }
    return options_.data_dir;
  }
  // ../shared/data beside the checkout holding scenes/: <checkout>/scenes/x.json.
  const std::filesystem::path beside =
      std::filesystem::absolute(file_).parent_path().parent_path().parent_path() / "shared" /
      "data";
  const std::optional<std::filesystem::path> root = find_data_dir(beside);
  if (!root) {
    fail(ptr, "needs the real-data folder: set HAPSIM_DATA or give --data DIR (looked in " +
                  beside.lexically_normal().string() + ")");
  }
  std::filesystem::path dir = *root / data_default_;
  std::error_code ec;
  if (!std::filesystem::is_directory(dir, ec)) {
    fail(ptr, "needs the data folder " + dir.string() + ", which does not exist; give --data DIR");
  }
  return dir;
}

std::string ascii_lower(std::string s) {
  std::transform(s.begin(), s.end(), s.begin(),
                 [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  return s;
}

}  // namespace hapsim
