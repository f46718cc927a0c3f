// Writing a command's output files so that a failed write is said: a full disk (or /dev/full)
// makes fprintf and ofstream fail silently until the buffer is flushed, and a command that exits
// 0 having written nothing is worse than one that stops. Every file goes through
// core/atomic_file.h (a temporary, fsync, rename): the user's old file stays whole on a failure.
// Failures become CommandError "OPTION PATH: what (reason)": one line, exit 2.
#pragma once

#include "commands.h"
#include "hapsim/core/atomic_file.h"
#include "hapsim/core/error.h"

#include <nlohmann/json.hpp>

#include <cerrno>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <memory>
#include <optional>
#include <string>
#include <string_view>

namespace hapsim::app {

/// The CommandError for `e`, a failure writing `path` given as `option`.
inline CommandError output_error(const std::string& option, const std::string& path,
                                 const Error& e) {
  return CommandError(option + " " + path + ": " + e.detail());
}

/// Opens `path` (given as `option`) for an atomic write now, so a bad path fails before the work.
inline std::unique_ptr<AtomicFile> open_output(const std::string& option, const std::string& path) {
  try {
    return std::make_unique<AtomicFile>(path);
  } catch (const Error& e) {
    throw output_error(option, path, e);
  }
}

/// Writes `bytes` to `file` (opened by open_output) and commits it.
inline void commit_output(AtomicFile& file, const std::string& option, std::string_view bytes) {
  try {
    file.write(bytes);
    file.commit();
  } catch (const Error& e) {
    throw output_error(option, file.path().string(), e);
  }
}

/// Writes `bytes` to `path` atomically; throws CommandError naming `option` and the path.
inline void write_text_file(const std::string& option, const std::string& path,
                            std::string_view bytes) {
  commit_output(*open_output(option, path), option, bytes);
}

/// Writes `j` (indented) to `path` atomically; throws CommandError naming `option` and the path.
inline void write_json_file(const std::string& option, const std::string& path,
                            const nlohmann::json& j) {
  write_text_file(option, path, j.dump(2) + '\n');
}

/// `option PATH` written through a FILE* (fprintf), or standard output when PATH is empty. The
/// file is opened at construction (a bad path fails at once); the text is gathered in memory and
/// written atomically by commit(); nothing is written unless commit() is called.
class OutputFile {
 public:
  OutputFile(std::string option, std::string path)
      : option_(std::move(option)), path_(std::move(path)) {
    if (path_.empty()) {
      stream_ = stdout;
      return;
    }
    file_ = open_output(option_, path_);
    stream_ = ::open_memstream(&text_, &size_);
    if (stream_ == nullptr) {
      throw CommandError(option_ + " " + path_ + ": out of memory for the output");
    }
  }
  OutputFile(const OutputFile&) = delete;
  OutputFile& operator=(const OutputFile&) = delete;
  ~OutputFile() {
    if (stream_ != nullptr && stream_ != stdout) {
      std::fclose(stream_);
    }
    std::free(text_);
  }

  [[nodiscard]] std::FILE* get() const { return stream_; }
  [[nodiscard]] bool is_stdout() const { return stream_ == stdout; }
  /// Where a command's own messages go: stderr when the output is on stdout (pipes stay clean).
  [[nodiscard]] std::FILE* info() const { return is_stdout() ? stderr : stdout; }

  /// Writes the file (or flushes standard output); throws CommandError when any write failed.
  void commit() {
    if (is_stdout()) {
      const bool failed = std::ferror(stdout) != 0 || std::fflush(stdout) != 0;
      if (failed) {
        throw CommandError(std::string("standard output: write failed (") +
                           std::strerror(errno != 0 ? errno : EIO) + ")");
      }
      return;
    }
    const bool failed = std::ferror(stream_) != 0;
    const int closed = std::fclose(stream_);
    stream_ = nullptr;
    if (failed || closed != 0) {
      throw CommandError(option_ + " " + path_ + ": out of memory for the output");
    }
    commit_output(*file_, option_, std::string_view(text_, size_));
  }

 private:
  std::string option_;
  std::string path_;
  std::unique_ptr<AtomicFile> file_;
  std::FILE* stream_ = nullptr;
  char* text_ = nullptr;
  std::size_t size_ = 0;
};

/// Flushes and (unless it is stdout) closes `f`, which `option` PATH (or standard output) was
/// written through; throws CommandError when any write to it failed. Not atomic: new code uses
/// OutputFile or write_text_file.
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
