// A tiny file system of its own (a tmpfs of a few pages) for the tests of a full disk: mounting
// needs root (or CAP_SYS_ADMIN); where the mount is refused, mounted() is false and the test skips
// with why. /dev/full fails every write at once; this one fills after some bytes were written,
// which is what a real disk does.
#pragma once

#include <sys/mount.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <filesystem>
#include <string>

namespace hapsim::test {

class SmallTmpfs {
 public:
  /// Mounts a tmpfs of `size_kib` KiB at a fresh folder named after `name` and this process.
  explicit SmallTmpfs(const std::string& name, int size_kib = 64)
      : dir_(std::filesystem::temp_directory_path() /
             ("hapsim_full_" + name + "_" + std::to_string(::getpid()))) {
    std::error_code ec;
    std::filesystem::create_directories(dir_, ec);
    const std::string options = "size=" + std::to_string(size_kib) + "k";
    if (ec) {
      why_ = "cannot create " + dir_.string() + ": " + ec.message();
    } else if (::mount("tmpfs", dir_.c_str(), "tmpfs", 0, options.c_str()) != 0) {
      why_ = "cannot mount a small tmpfs (" + std::string(std::strerror(errno)) +
             "); needs root or CAP_SYS_ADMIN";
    } else {
      mounted_ = true;
    }
  }
  SmallTmpfs(const SmallTmpfs&) = delete;
  SmallTmpfs& operator=(const SmallTmpfs&) = delete;
  ~SmallTmpfs() {
    if (mounted_) {
      (void)::umount2(dir_.c_str(), MNT_DETACH);
    }
    std::error_code ec;
    std::filesystem::remove(dir_, ec);
  }

  [[nodiscard]] bool mounted() const { return mounted_; }
  /// Why it is not mounted.
  [[nodiscard]] const std::string& why_not() const { return why_; }
  [[nodiscard]] const std::filesystem::path& dir() const { return dir_; }

 private:
  std::filesystem::path dir_;
  bool mounted_ = false;
  std::string why_;
};

}  // namespace hapsim::test
