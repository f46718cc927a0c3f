// Parsing JSON text from a file a user gave us, so that no input can crash or hang the process
// and every failure names its place: nlohmann's SAX parser (iterative, no recursion) building the
// document while it tracks the JSON pointer of the value being read, with a nesting limit (a
// document nested tens of thousands deep would exhaust the stack wherever it is later walked
// recursively) and a number too large for a double (1e400) reported at its pointer.
#pragma once

#include <nlohmann/json.hpp>

#include <cstddef>
#include <string>
#include <string_view>

namespace hapsim {

/// Deeper than any scene needs (a CSG tree of a few dozen operations), far below the stack.
inline constexpr std::size_t kMaxJsonDepth = 100;

/// The document in `text`. Throws hapsim::Error whose where() is "<file>:<line>:<column>" for a
/// syntax error, "<file>:<JSON pointer>" for a number beyond a double's range or a value nested
/// deeper than `max_depth` arrays and objects.
[[nodiscard]] nlohmann::json parse_json_text(std::string_view text, const std::string& file,
                                             std::size_t max_depth = kMaxJsonDepth);

}  // namespace hapsim
