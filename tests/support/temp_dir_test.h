// A gtest fixture with a folder of its own per test (named after the suite, the test and the
// process), created empty before the test and removed after it, and a way to write files into it.
#pragma once

#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <string>

namespace hapsim::test {

class TempDirTest : public ::testing::Test {
 protected:
  void SetUp() override {
    const ::testing::TestInfo* info = ::testing::UnitTest::GetInstance()->current_test_info();
    std::string name = "hapsim_" + std::string(info->test_suite_name()) + "_" +
                       std::to_string(::getpid()) + "_" + info->name();
    // Parameterised suites and tests carry '/' in their names: keep one folder level.
    for (char& c : name) {
      if (c == '/')
        c = '_';
    }
    dir_ = std::filesystem::temp_directory_path() / name;
    std::filesystem::remove_all(dir_);
    std::filesystem::create_directories(dir_);
  }
  void TearDown() override { std::filesystem::remove_all(dir_); }

  /// Writes `text` to `name` (folders created) under the test's folder; returns its path.
  std::filesystem::path write(const std::string& name, const std::string& text) const {
    const std::filesystem::path p = dir_ / name;
    std::filesystem::create_directories(p.parent_path());
    std::ofstream(p, std::ios::binary) << text;
    return p;
  }

  std::filesystem::path dir_;
};

}  // namespace hapsim::test
