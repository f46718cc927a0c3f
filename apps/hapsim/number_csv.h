// Reading rows of numbers from CSV (`hapsim query` points, `hapsim fk` joint rows, `hapsim ik`
// poses): a first row that is not numeric is a header; blank lines and '#' lines are skipped.
#pragma once

#include <filesystem>
#include <string>
#include <string_view>
#include <vector>

namespace hapsim::app {

/// Reads rows of exactly `columns` finite numbers; `names` (e.g. "x,y,z") and `what` (e.g.
/// "points") word the messages. Throws hapsim::Error naming the file and line for a wrong column
/// count, a non-number, NaN/inf, or no rows at all.
std::vector<std::vector<double>> read_number_rows_csv(const std::filesystem::path& path,
                                                      std::size_t columns, const std::string& names,
                                                      const std::string& what);

/// The same from CSV text; `where` (a file name) prefixes every error as "where:line".
std::vector<std::vector<double>> parse_number_rows_csv(std::string_view text,
                                                       const std::string& where,
                                                       std::size_t columns,
                                                       const std::string& names,
                                                       const std::string& what);

}  // namespace hapsim::app
