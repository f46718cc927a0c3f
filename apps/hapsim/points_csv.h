// Reading query points from CSV (`x,y,z` rows, optional header) for `hapsim query`.
#pragma once

#include "hapsim/core/types.h"

#include <filesystem>
#include <vector>

namespace hapsim::app {

/// Reads `x,y,z` rows. A first row that is not numeric is taken as a header; blank lines and
/// lines starting with '#' are skipped. Throws hapsim::Error naming the file and line for
/// anything else (wrong column count, non-numbers, NaN/inf, no rows).
std::vector<Vec3> read_points_csv(const std::filesystem::path& path);

}  // namespace hapsim::app
