// Locating the optional real-data folder (../shared/data beside a checkout). Tests and benchmarks
// that use it skip with a message when it is absent; nothing in the product requires it.
#pragma once

#include <filesystem>
#include <optional>

namespace hapsim {

/// The real-data folder: $HAPSIM_DATA if set and existing, else `fallback` if it exists.
std::optional<std::filesystem::path> find_data_dir(const std::filesystem::path& fallback = {});

}  // namespace hapsim
