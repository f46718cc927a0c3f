#include "number_csv.h"

#include "hapsim/core/error.h"
#include "hapsim/core/text_file.h"

#include <charconv>
#include <cmath>
#include <sstream>
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

// A row as quoted in a message: one line, cut to 60 characters.
std::string shown(std::string_view row) {
  return row.size() > 60 ? std::string(row.substr(0, 57)) + "..." : std::string(row);
}

}  // namespace

std::vector<std::vector<double>> read_number_rows_csv(const std::filesystem::path& path,
                                                      std::size_t columns, const std::string& names,
                                                      const std::string& what) {
  std::error_code ec;
  if (!std::filesystem::is_regular_file(path, ec)) {
    throw Error(path.string(), "no such " + what + " file (expected a CSV of " + names + " rows)");
  }
  constexpr std::size_t kMaxCsvBytes = std::size_t{256} << 20;
  return parse_number_rows_csv(read_text_file(path, kMaxCsvBytes, what + " CSV"), path.string(),
                               columns, names, what);
}

std::vector<std::vector<double>> parse_number_rows_csv(std::string_view text,
                                                       const std::string& where,
                                                       std::size_t columns,
                                                       const std::string& names,
                                                       const std::string& what) {
  std::istringstream in{std::string(text)};
  std::vector<std::vector<double>> rows;
  std::string line;
  std::size_t line_number = 0;
  bool first_data_row = true;
  while (std::getline(in, line)) {
    ++line_number;
    const std::string_view row = trim(line);
    if (row.empty() || row.front() == '#') {
      continue;
    }
    std::vector<double> values(columns, 0.0);
    std::size_t fields = 0;
    bool numeric = true;
    std::size_t start = 0;
    while (start <= row.size()) {
      const std::size_t comma = row.find(',', start);
      const std::string_view field = row.substr(
          start, comma == std::string_view::npos ? std::string_view::npos : comma - start);
      if (fields < columns && !parse_double(field, &values[fields])) {
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
    if (fields != columns) {
      throw Error(at, "expected " + std::to_string(columns) + " columns " + names + ", got " +
                          std::to_string(fields));
    }
    if (!numeric) {
      throw Error(at, "expected numbers " + names + ", got '" + shown(row) + "'");
    }
    for (const double v : values) {
      if (!std::isfinite(v)) {
        throw Error(at, "values must be finite, got '" + shown(row) + "'");
      }
    }
    rows.push_back(std::move(values));
  }
  if (rows.empty()) {
    throw Error(where, "no " + what + ": expected rows of " + names);
  }
  return rows;
}

}  // namespace hapsim::app
