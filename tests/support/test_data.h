// The real-data folder (../shared/data) for the tests: $HAPSIM_DATA when set, else the path
// configured at build time (find_data_dir). HAPSIM_REQUIRE_DATA=1 (CI sets it through
// scripts/run-tests.sh) turns a missing data set into a failure, so the real-data tests (the KDL
// oracle, the data goldens) cannot pass by skipping.
#pragma once

#include "hapsim/core/data_dir.h"

#include <cstdlib>
#include <filesystem>
#include <optional>
#include <string_view>

#include <gtest/gtest.h>

namespace hapsim::test {

/// HAPSIM_REQUIRE_DATA=1: a test whose real data is missing fails instead of skipping.
inline bool data_required() {
  const char* v = std::getenv("HAPSIM_REQUIRE_DATA");
  return v != nullptr && std::string_view(v) == "1";
}

/// The real-data folder, if there is one.
inline std::optional<std::filesystem::path> data_dir() {
  return find_data_dir(HAPSIM_TEST_DATA_DIR);
}

/// `relative` inside the real-data folder (inside the configured path when there is none, so a
/// message can say where it looked).
inline std::filesystem::path data_path(const std::filesystem::path& relative) {
  return data_dir().value_or(std::filesystem::path(HAPSIM_TEST_DATA_DIR)) / relative;
}

}  // namespace hapsim::test

/// In a test body: unless `present`, skip (or, with HAPSIM_REQUIRE_DATA=1, fail) saying `what`
/// is missing. A macro because GTEST_SKIP and FAIL return from the test function.
#define HAPSIM_SKIP_WITHOUT_DATA(present, what)                                                   \
  do {                                                                                            \
    if (!(present)) {                                                                             \
      if (::hapsim::test::data_required()) {                                                      \
        FAIL() << what << " (HAPSIM_REQUIRE_DATA=1: the real data must be present)";              \
      }                                                                                           \
      GTEST_SKIP() << what << " (real-data tests skip; set HAPSIM_DATA or place ../shared/data)"; \
    }                                                                                             \
  } while (false)
