#include "hapsim/core/text_file.h"

#include "hapsim/core/error.h"
#include "support/temp_path.h"

#include <gtest/gtest.h>

#include <fstream>
#include <string>

namespace hapsim {
namespace {

std::string error_of(const std::filesystem::path& path, std::size_t max_bytes) {
  try {
    (void)read_text_file(path, max_bytes, "trajectory CSV");
  } catch (const Error& e) {
    EXPECT_EQ(e.where(), path.string());
    return e.detail();
  }
  return "";
}

TEST(TextFile, ReadsAWholeFileUpToTheBound) {
  const auto path = test::temp_path(".csv");
  const std::string text(200'000, 'a');
  std::ofstream(path) << text;
  EXPECT_EQ(read_text_file(path, text.size(), "trajectory CSV"), text);
  EXPECT_NE(error_of(path, text.size() - 1).find("larger than 199999 bytes"), std::string::npos);
  std::filesystem::remove(path);
}

TEST(TextFile, DevZeroIsRefusedAtOnceNotReadForEver) {
  EXPECT_NE(
      error_of("/dev/zero", std::size_t{1} << 30).find("not a text file (a NUL byte at byte 0)"),
      std::string::npos);
}

TEST(TextFile, MissingAndFolderAreSaid) {
  EXPECT_NE(error_of("/nonexistent/t.csv", 100).find("cannot open the trajectory CSV"),
            std::string::npos);
  EXPECT_NE(error_of("/tmp", 100).find("is a folder"), std::string::npos);
}

}  // namespace
}  // namespace hapsim
