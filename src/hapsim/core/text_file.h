// Reading a whole text input file (scene, trajectory, URDF, CSV) into memory with a bound: a path
// a user gives may be /dev/zero, a FIFO or a file far larger than any of these, and reading it
// unbounded ends in bad_alloc or never. A NUL byte ends the read at once: text has none, and
// /dev/zero or a binary file given by mistake is said in its first kilobytes. Every failure is a
// hapsim::Error naming the file.
#pragma once

#include <cstddef>
#include <filesystem>
#include <string>
#include <string_view>

namespace hapsim {

/// The contents of `path`, at most `max_bytes` of them. `what` ("scene file", "trajectory")
/// names the kind of file in messages. Throws hapsim::Error(path, ...) when the path is missing,
/// a folder, unreadable, holds more than `max_bytes` or a NUL byte (not text).
[[nodiscard]] std::string read_text_file(const std::filesystem::path& path, std::size_t max_bytes,
                                         std::string_view what);

}  // namespace hapsim
