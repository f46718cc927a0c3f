// Errors that carry *where* (a file, a JSON path, a packet field, a CLI option) apart from
// *what* went wrong, so every message a user sees names both.
#pragma once

#include <stdexcept>
#include <string>

namespace hapsim {

class Error : public std::runtime_error {
 public:
  /// `where`: e.g. "knee.stl", "scene.json:/bodies/2/material", "--points". `what`: what was
  /// wrong and what was expected.
  Error(std::string where, const std::string& what);

  [[nodiscard]] const std::string& where() const noexcept { return where_; }
  [[nodiscard]] const std::string& detail() const noexcept { return detail_; }

 private:
  std::string where_;
  std::string detail_;
};

}  // namespace hapsim
