// Reading scene JSON so that every error names its place: a hapsim::Error whose where() is
// "<file>:<JSON pointer>" and whose message says what was expected. The scene parser and the
// readers of its parts (CSG solids, csg_reader.h) share these checks, so a pose or a number range
// reads and fails the same way wherever it appears.
#pragma once

#include "hapsim/core/types.h"

#include <nlohmann/json.hpp>

#include <cstddef>
#include <filesystem>
#include <initializer_list>
#include <string>
#include <utility>

namespace hapsim {

class JsonReader {
 public:
  using Json = nlohmann::json;

  /// `file` names the document in every error.
  explicit JsonReader(std::filesystem::path file) : file_(std::move(file)) {}

  [[nodiscard]] const std::filesystem::path& file() const { return file_; }

  /// Throws hapsim::Error("<file>:<ptr>", what); an empty pointer is shown as "/".
  [[noreturn]] void fail(const std::string& ptr, const std::string& what) const;

  /// `ptr` extended by an object key (escaped per RFC 6901) or an array index.
  [[nodiscard]] static std::string at(const std::string& ptr, const std::string& key);
  [[nodiscard]] static std::string at(const std::string& ptr, std::size_t index);
  /// "a number", "an object" … for messages.
  [[nodiscard]] static std::string type_name(const Json& j);
  /// The value as JSON text, cut to about 40 characters, for messages.
  [[nodiscard]] static std::string shown(const Json& j);

  /// `j` if it is an object (array), else an error saying `what` was expected.
  const Json& object(const Json& j, const std::string& ptr, const std::string& what) const;
  const Json& array(const Json& j, const std::string& ptr, const std::string& what) const;
  /// An error at the first key of `obj` not in `allowed`, listing the allowed ones.
  void allow_keys(const Json& obj, const std::string& ptr,
                  std::initializer_list<const char*> allowed) const;
  /// obj[key], or an error at `ptr` naming the missing key.
  const Json& required(const Json& obj, const std::string& ptr, const char* key) const;
  /// A finite number (`unit` is named in the message).
  [[nodiscard]] double number(const Json& j, const std::string& ptr, const std::string& unit) const;
  /// obj[key] as a number in [lo, hi] (open at lo when lo_open; the string "inf" allowed when
  /// inf_allowed), or `fallback` when the key is absent.
  [[nodiscard]] double number_in(const Json& obj, const std::string& ptr, const char* key,
                                 double fallback, double lo, double hi, const std::string& unit,
                                 bool lo_open = false, bool inf_allowed = false) const;
  /// `j` if it is true or false.
  [[nodiscard]] bool boolean(const Json& j, const std::string& ptr) const;
  [[nodiscard]] std::string string(const Json& j, const std::string& ptr,
                                   const std::string& what) const;
  [[nodiscard]] std::string nonempty_string(const Json& j, const std::string& ptr,
                                            const std::string& what) const;
  /// `j` if it is one of the `choices` strings, else an error listing them.
  std::string one_of(const Json& j, const std::string& ptr,
                     std::initializer_list<const char*> choices) const;
  /// [x, y, z], three finite numbers.
  [[nodiscard]] Vec3 vec3(const Json& j, const std::string& ptr, const std::string& unit) const;
  /// A pose {position_m, rotation_deg | quaternion_wxyz} (docs/scene-format.md) as X_parent_child.
  [[nodiscard]] Iso3 parse_pose(const Json& j, const std::string& ptr) const;

 protected:
  std::filesystem::path file_;
};

}  // namespace hapsim
