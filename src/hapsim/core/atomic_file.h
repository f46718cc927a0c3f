// Writing an output file whole or not at all. A command that writes through a plain ofstream on a
// full disk learns of it only if it checks after a flush, and even then leaves a truncated file
// where the user's old one was. Here the bytes go to a temporary beside the target, are fsynced,
// and the temporary is renamed over the target: a reader sees the old file or the complete new
// one, never a part. Every failure (open, short write, fsync, close, rename) is a hapsim::Error
// naming the path and the system's reason, so callers turn it into one line and a non-zero exit.
//
// A target that exists and is not a regular file (/dev/stdout, /dev/full, a FIFO, a terminal) is
// written in place: renaming over a device would replace it. A FIFO without a reader is refused,
// not waited on.
#pragma once

#include <cstddef>
#include <filesystem>
#include <functional>
#include <string>
#include <string_view>

namespace hapsim {

class AtomicFile {
 public:
  /// Creates the temporary beside `path` (or opens a non-regular `path` itself). Throws
  /// hapsim::Error(path, ...) when it cannot: a missing folder, no permission, a folder as path.
  explicit AtomicFile(std::filesystem::path path);
  /// Removes the temporary unless commit() succeeded: the target keeps what it held.
  ~AtomicFile();
  AtomicFile(const AtomicFile&) = delete;
  AtomicFile& operator=(const AtomicFile&) = delete;

  /// Appends `bytes` (buffered). Throws hapsim::Error naming the path on a failed write.
  void write(std::string_view bytes);
  /// Writes out what is buffered and fsyncs it, short of the rename: a caller with several files
  /// that belong together syncs them all before it commits any. Throws hapsim::Error on failure.
  void sync();
  /// Flushes, fsyncs and closes the temporary and renames it over the target (then fsyncs the
  /// folder, so the rename itself survives a power cut). Throws hapsim::Error on any failure,
  /// leaving the target as it was.
  void commit();

  /// The path as given.
  [[nodiscard]] const std::filesystem::path& path() const noexcept { return path_; }

 private:
  void flush_buffer();
  [[noreturn]] void fail(const std::string& what, int error_number);
  void discard() noexcept;

  std::filesystem::path path_;    // as given, for messages
  std::filesystem::path target_;  // where the rename goes (symbolic links followed)
  std::filesystem::path temp_;    // empty when writing a non-regular target in place
  int fd_ = -1;
  bool committed_ = false;
  std::string buffer_;
};

/// Writes `bytes` to `path` atomically (AtomicFile: open, write, commit).
void write_file_atomically(const std::filesystem::path& path, std::string_view bytes);

/// Writes to `path` atomically whatever `writer` appends through the AtomicFile it is given.
void write_file_atomically(const std::filesystem::path& path,
                           const std::function<void(AtomicFile&)>& writer);

}  // namespace hapsim
