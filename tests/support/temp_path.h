// A unique temporary path per test and process, shared by the test suites.
#pragma once

#include <unistd.h>

#include <filesystem>
#include <string>

#include <gtest/gtest.h>

namespace hapsim::test {

/// A fresh path in the temp folder, unique per test and process (tests may run in parallel).
inline std::filesystem::path temp_path(const std::string& suffix) {
  const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
  const std::string name = std::string(info->test_suite_name()) + "_" + info->name();
  return std::filesystem::temp_directory_path() /
         ("hapsim_" + name + "_" + std::to_string(::getpid()) + suffix);
}

}  // namespace hapsim::test
