// Writing a command's output files so that a failed write is said: a full disk (or /dev/full)
// makes fprintf and ofstream fail silently until the buffer is flushed, and a command that exits
// 0 having written nothing is worse than one that stops.
#pragma once

#include "commands.h"

#include <nlohmann/json.hpp>

#include <cerrno>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <string>

namespace hapsim::app {

/// Writes `j` (indented) to `path`; throws CommandError naming `option` and the path when it
/// cannot be opened or written.
inline void write_json_file(const std::string& option, const std::string& path,
                            const nlohmann::json& j) {
  std::ofstream out(path);
  if (!out) {
    throw CommandError(option + " " + path + ": cannot open for writing (" + std::strerror(errno) +
                       ")");
  }
  out << j.dump(2) << '\n';
  out.flush();
  if (!out) {
    throw CommandError(option + " " + path + ": write failed (" + std::strerror(errno) + ")");
  }
}

/// Flushes and (unless it is stdout) closes `f`, which `option` PATH (or standard output) was
/// written through; throws CommandError when any write to it failed.
inline void close_checked(std::FILE* f, const std::string& option, const std::string& path) {
  const bool failed_before = std::ferror(f) != 0;
  const bool flush_failed = std::fflush(f) != 0;
  const int err = errno;
  const bool close_failed = f != stdout && std::fclose(f) != 0;
  if (failed_before || flush_failed || close_failed) {
    const std::string target = f == stdout ? std::string("standard output") : option + " " + path;
    throw CommandError(target + ": write failed (" + std::strerror(err != 0 ? err : EIO) + ")");
  }
}

}  // namespace hapsim::app
