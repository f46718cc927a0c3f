#include "points_csv.h"

#include "hapsim/core/error.h"

#include <charconv>
#include <cmath>
#include <fstream>
#include <string>
#include <string_view>
#include <system_error>

namespace hapsim::app {
namespace {

std::string_view trim(std::string_view s) {
  while (!s.empty() && (s.front() == ' ' || s.front() == '\t')) {
    s.remove_prefix(1);
  }
  while (!s.empty() && (s.back() == ' ' || s.back() == '\t' || s.back() == '\r')) {
    s.remove_suffix(1);
  }
  return s;
}

// Parses one field as a double; false if it is not entirely a number.
bool parse_double(std::string_view field, double* out) {
  field = trim(field);
  if (field.empty()) {
    return false;
  }
  if (field.front() == '+') {
    field.remove_prefix(1);
  }
  const char* end = field.data() + field.size();
  const auto [ptr, ec] = std::from_chars(field.data(), end, *out);
  return ec == std::errc() && ptr == end;
}

}  // namespace

std::vector<Vec3> read_points_csv(const std::filesystem::path& path) {
  const std::string where = path.string();
  std::error_code ec;
  if (!std::filesystem::is_regular_file(path, ec)) {
    throw Error(where, "no such points file (expected a CSV of x,y,z rows)");
  }
  std::ifstream in(path);
  if (!in) {
    throw Error(where, "cannot open the points file");
  }
  std::vector<Vec3> points;
  std::string line;
  std::size_t line_number = 0;
  bool first_data_row = true;
  while (std::getline(in, line)) {
    ++line_number;
    const std::string_view row = trim(line);
    if (row.empty() || row.front() == '#') {
      continue;
    }
    double xyz[3] = {0.0, 0.0, 0.0};
    int fields = 0;
    bool numeric = true;
    std::size_t start = 0;
    while (start <= row.size()) {
      const std::size_t comma = row.find(',', start);
      const std::string_view field = row.substr(
          start, comma == std::string_view::npos ? std::string_view::npos : comma - start);
      if (fields < 3 && !parse_double(field, &xyz[fields])) {
        numeric = false;
      }
      ++fields;
      if (comma == std::string_view::npos) {
        break;
      }
      start = comma + 1;
    }
    const std::string at = where + ":" + std::to_string(line_number);
    if (!numeric && first_data_row) {
      first_data_row = false;  // a header row such as "x,y,z"
      continue;
    }
    first_data_row = false;
    if (fields != 3) {
      throw Error(at, "expected 3 columns x,y,z, got " + std::to_string(fields));
    }
    if (!numeric) {
      throw Error(at, "expected numbers x,y,z, got '" + std::string(row) + "'");
    }
    if (!std::isfinite(xyz[0]) || !std::isfinite(xyz[1]) || !std::isfinite(xyz[2])) {
      throw Error(at, "coordinates must be finite, got '" + std::string(row) + "'");
    }
    points.emplace_back(xyz[0], xyz[1], xyz[2]);
  }
  if (in.bad()) {
    throw Error(where, "read error");
  }
  if (points.empty()) {
    throw Error(where, "no points: expected rows of x,y,z");
  }
  return points;
}

}  // namespace hapsim::app
