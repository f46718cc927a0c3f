// The tests' real-data switches (tests/support/test_data.h): $HAPSIM_DATA wins over the configured
// folder, and with HAPSIM_REQUIRE_DATA=1 a missing data set is a failure, not a skip.
#include "support/temp_path.h"
#include "support/test_data.h"

#include <gtest/gtest-spi.h>
#include <gtest/gtest.h>

#include <cstdlib>
#include <filesystem>
#include <optional>
#include <string>

namespace hapsim {
namespace {

// Sets an environment variable for one scope, then puts back what was there.
class ScopedEnv {
 public:
  ScopedEnv(const char* name, const char* value) : name_(name) {
    if (const char* old = std::getenv(name)) {
      old_ = old;
    }
    ::setenv(name, value, 1);
  }
  ~ScopedEnv() {
    if (old_) {
      ::setenv(name_, old_->c_str(), 1);
    } else {
      ::unsetenv(name_);
    }
  }
  ScopedEnv(const ScopedEnv&) = delete;
  ScopedEnv& operator=(const ScopedEnv&) = delete;

 private:
  const char* name_;
  std::optional<std::string> old_;
};

TEST(TestDataSwitch, HapsimDataWinsOverTheConfiguredFolder) {
  const std::filesystem::path elsewhere = test::temp_path("elsewhere-data");
  std::filesystem::create_directories(elsewhere / "motoman_gp7");
  const ScopedEnv data("HAPSIM_DATA", elsewhere.c_str());
  ASSERT_TRUE(test::data_dir().has_value());
  EXPECT_EQ(*test::data_dir(), elsewhere);
  EXPECT_EQ(test::data_path("motoman_gp7/gp7.urdf"), elsewhere / "motoman_gp7/gp7.urdf");
}

void without_data() {
  HAPSIM_SKIP_WITHOUT_DATA(false, "the test's data set");
}

TEST(TestDataSwitch, RequiredDataThatIsMissingFails) {
  const ScopedEnv require("HAPSIM_REQUIRE_DATA", "1");
  EXPECT_FATAL_FAILURE(without_data(), "HAPSIM_REQUIRE_DATA=1");
}

TEST(TestDataSwitch, OnlyOneRequiresTheData) {
  {
    const ScopedEnv require("HAPSIM_REQUIRE_DATA", "0");
    EXPECT_FALSE(test::data_required());
  }
  const ScopedEnv require("HAPSIM_REQUIRE_DATA", "1");
  EXPECT_TRUE(test::data_required());
}

}  // namespace
}  // namespace hapsim
