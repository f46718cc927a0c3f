#include "hapsim/core/atomic_file.h"

#include "hapsim/core/error.h"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <atomic>
#include <cerrno>
#include <cstring>
#include <system_error>
#include <utility>

namespace hapsim {

namespace {

// Writes are gathered to this size before a system call: callers may append line by line.
constexpr std::size_t kBufferBytes = 64 * 1024;

std::string reason(int error_number) {
  return std::strerror(error_number);
}

// A name beside the target that no other writer (thread or process) picks at the same time.
std::filesystem::path temporary_beside(const std::filesystem::path& target) {
  static std::atomic<unsigned> counter{0};
  // Appended piecewise: GCC 12 warns falsely (stringop-overflow) on "." + std::string.
  std::string name(".");
  name += target.filename().string();
  name += ".tmp-";
  name += std::to_string(::getpid());
  name += '-';
  name += std::to_string(counter.fetch_add(1));
  std::filesystem::path temp = target.parent_path();
  temp /= name;
  return temp;
}

}  // namespace

AtomicFile::AtomicFile(std::filesystem::path path) : path_(std::move(path)), target_(path_) {
  if (path_.empty()) {
    throw Error("", "no output path given");
  }
  struct stat st {};
  const bool exists = ::stat(path_.c_str(), &st) == 0;
  if (exists && S_ISDIR(st.st_mode)) {
    throw Error(path_.string(), "is a folder, expected a file to write");
  }
  if (exists && !S_ISREG(st.st_mode)) {
    // A device, FIFO or socket: written in place. O_NONBLOCK so a FIFO nobody reads is refused
    // (ENXIO) rather than waited on; cleared again for the writes.
    fd_ = ::open(path_.c_str(), O_WRONLY | O_NONBLOCK | O_NOCTTY | O_CLOEXEC);
    if (fd_ < 0) {
      const int err = errno;
      throw Error(path_.string(), err == ENXIO ? std::string("a FIFO nobody reads; not waiting")
                                               : "cannot open for writing (" + reason(err) + ")");
    }
    const int flags = ::fcntl(fd_, F_GETFL);
    if (flags >= 0) {
      (void)::fcntl(fd_, F_SETFL, flags & ~O_NONBLOCK);
    }
    return;
  }
  if (exists) {
    // A symbolic link keeps pointing at the (replaced) file it names.
    std::error_code ec;
    std::filesystem::path resolved = std::filesystem::canonical(path_, ec);
    if (!ec) {
      target_ = std::move(resolved);
    }
  }
  temp_ = temporary_beside(target_);
  fd_ = ::open(temp_.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_CLOEXEC, 0666);
  if (fd_ < 0) {
    const int err = errno;
    temp_.clear();
    throw Error(path_.string(), "cannot open for writing (" + reason(err) + ")");
  }
  if (exists) {
    (void)::fchmod(fd_, st.st_mode & 07777);  // a replaced file keeps its permissions
  }
}

AtomicFile::~AtomicFile() {
  if (!committed_) {
    discard();
  }
}

void AtomicFile::write(std::string_view bytes) {
  if (fd_ < 0) {
    throw Error(path_.string(), "write after the file was closed");
  }
  buffer_.append(bytes);
  if (buffer_.size() >= kBufferBytes) {
    flush_buffer();
  }
}

void AtomicFile::flush_buffer() {
  std::size_t done = 0;
  while (done < buffer_.size()) {
    const ssize_t n = ::write(fd_, buffer_.data() + done, buffer_.size() - done);
    if (n < 0 && errno == EINTR) {
      continue;
    }
    if (n <= 0) {
      fail("write failed", n < 0 ? errno : ENOSPC);
    }
    done += static_cast<std::size_t>(n);
  }
  buffer_.clear();
}

void AtomicFile::sync() {
  if (fd_ < 0) {
    throw Error(path_.string(), "sync after the file was closed");
  }
  flush_buffer();
  if (!temp_.empty() && ::fsync(fd_) != 0) {
    fail("fsync failed", errno);
  }
}

void AtomicFile::commit() {
  sync();
  const int fd = std::exchange(fd_, -1);
  if (::close(fd) != 0) {
    fail("write failed on close", errno);
  }
  if (temp_.empty()) {
    committed_ = true;
    return;
  }
  if (::rename(temp_.c_str(), target_.c_str()) != 0) {
    fail("cannot move the written file into place", errno);
  }
  temp_.clear();
  committed_ = true;
  // The rename is durable once the folder is synced; a file system that cannot sync folders
  // (EINVAL) has nothing more to give.
  const std::filesystem::path folder =
      target_.has_parent_path() ? target_.parent_path() : std::filesystem::path(".");
  const int dir = ::open(folder.c_str(), O_RDONLY | O_DIRECTORY | O_CLOEXEC);
  if (dir >= 0) {
    const bool synced = ::fsync(dir) == 0 || errno == EINVAL;
    const int err = errno;
    ::close(dir);
    if (!synced) {
      throw Error(path_.string(), "written, but syncing its folder failed (" + reason(err) + ")");
    }
  }
}

void AtomicFile::fail(const std::string& what, int error_number) {
  discard();
  throw Error(path_.string(), what + " (" + reason(error_number) + ")");
}

void AtomicFile::discard() noexcept {
  if (fd_ >= 0) {
    ::close(fd_);
    fd_ = -1;
  }
  if (!temp_.empty()) {
    ::unlink(temp_.c_str());
    temp_.clear();
  }
  buffer_.clear();
}

void write_file_atomically(const std::filesystem::path& path, std::string_view bytes) {
  AtomicFile file(path);
  file.write(bytes);
  file.commit();
}

void write_file_atomically(const std::filesystem::path& path,
                           const std::function<void(AtomicFile&)>& writer) {
  AtomicFile file(path);
  writer(file);
  file.commit();
}

}  // namespace hapsim
