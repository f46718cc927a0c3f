#include "hapsim/core/data_dir.h"

#include <cstdlib>
#include <system_error>

namespace hapsim {

std::optional<std::filesystem::path> find_data_dir(const std::filesystem::path& fallback) {
  std::error_code ec;
  if (const char* env = std::getenv("HAPSIM_DATA"); env != nullptr && *env != '\0') {
    if (std::filesystem::is_directory(env, ec)) {
      return std::filesystem::path(env);
    }
  }
  if (!fallback.empty() && std::filesystem::is_directory(fallback, ec)) {
    return fallback;
  }
  return std::nullopt;
}

}  // namespace hapsim
