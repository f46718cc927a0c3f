#include "hapsim/core/atomic_file.h"

#include "hapsim/core/error.h"
#include "support/small_tmpfs.h"
#include "support/temp_dir_test.h"

#include <sys/stat.h>
#include <sys/types.h>

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>

namespace hapsim {
namespace {

namespace fs = std::filesystem;

std::string contents(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

std::size_t entries(const fs::path& dir) {
  return static_cast<std::size_t>(std::distance(fs::directory_iterator(dir), {}));
}

// The message of the hapsim::Error `f` throws, checked to name `path`; "" when none is thrown.
template <typename F>
std::string error_of(const fs::path& path, F&& f) {
  try {
    f();
  } catch (const Error& e) {
    EXPECT_EQ(e.where(), path.string());
    return e.detail();
  }
  return "";
}

using AtomicFileTest = test::TempDirTest;

TEST_F(AtomicFileTest, WritesTheBytesAndLeavesNoTemporary) {
  const fs::path p = dir_ / "out.csv";
  const std::string text(300'000, 'x');  // more than one buffer's worth
  write_file_atomically(p, text);
  EXPECT_EQ(contents(p), text);
  EXPECT_EQ(entries(dir_), 1u);
}

TEST_F(AtomicFileTest, ReplacesAFileKeepingItsPermissions) {
  const fs::path p = write("out.json", "old");
  ASSERT_EQ(::chmod(p.c_str(), 0640), 0);
  write_file_atomically(p, [](AtomicFile& f) {
    f.write("new ");
    f.write("text");
  });
  EXPECT_EQ(contents(p), "new text");
  struct stat st {};
  ASSERT_EQ(::stat(p.c_str(), &st), 0);
  EXPECT_EQ(st.st_mode & 07777, 0640u);
}

TEST_F(AtomicFileTest, AnUncommittedFileLeavesTheOldOneAndNoTemporary) {
  const fs::path p = write("out.json", "old");
  {
    AtomicFile f(p);
    f.write(std::string(200'000, 'n'));
  }
  EXPECT_EQ(contents(p), "old");
  EXPECT_EQ(entries(dir_), 1u);
}

TEST_F(AtomicFileTest, ASymbolicLinkStaysALinkToTheNewFile) {
  const fs::path real = write("real.txt", "old");
  const fs::path link = dir_ / "link.txt";
  fs::create_symlink(real, link);
  write_file_atomically(link, "new");
  EXPECT_TRUE(fs::is_symlink(link));
  EXPECT_EQ(contents(real), "new");
}

TEST_F(AtomicFileTest, AMissingFolderOrAFolderAsPathIsSaid) {
  const fs::path missing = dir_ / "no" / "such" / "out.csv";
  EXPECT_NE(error_of(missing, [&] { write_file_atomically(missing, "x"); })
                .find("cannot open for writing (No such file or directory)"),
            std::string::npos);
  EXPECT_NE(error_of(dir_, [&] { write_file_atomically(dir_, "x"); }).find("is a folder"),
            std::string::npos);
}

TEST(AtomicFile, DevFullIsWrittenInPlaceAndItsFailureSaid) {
  if (!fs::exists("/dev/full")) {
    GTEST_SKIP() << "no /dev/full on this system";
  }
  EXPECT_NE(error_of("/dev/full", [] { write_file_atomically("/dev/full", "x"); })
                .find("write failed (No space left on device)"),
            std::string::npos);
  EXPECT_TRUE(fs::is_character_file("/dev/full"));  // not replaced by a rename
}

TEST_F(AtomicFileTest, AFifoNobodyReadsIsRefusedNotWaitedOn) {
  const fs::path fifo = dir_ / "fifo";
  ASSERT_EQ(::mkfifo(fifo.c_str(), 0600), 0);
  EXPECT_NE(error_of(fifo, [&] { write_file_atomically(fifo, "x"); }).find("FIFO nobody reads"),
            std::string::npos);
}

TEST(AtomicFile, AFullDiskIsSaidAndTheOldFileKept) {
  const test::SmallTmpfs disk("atomic_file");
  if (!disk.mounted()) {
    GTEST_SKIP() << disk.why_not();
  }
  const fs::path p = disk.dir() / "out.bin";
  write_file_atomically(p, "old");
  const std::string big(256 * 1024, 'b');  // four times the disk
  EXPECT_NE(error_of(p, [&] { write_file_atomically(p, big); })
                .find("write failed (No space left on device)"),
            std::string::npos);
  EXPECT_EQ(contents(p), "old");
  EXPECT_EQ(entries(disk.dir()), 1u);  // the temporary is gone
}

}  // namespace
}  // namespace hapsim
