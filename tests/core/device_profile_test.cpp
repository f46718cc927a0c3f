#include "hapsim/core/device_profile.h"

#include "hapsim/core/device_io.h"
#include "hapsim/core/error.h"
#include "support/test_data.h"

#include <cmath>
#include <fstream>
#include <regex>
#include <sstream>
#include <string>
#include <vector>

#include <gtest/gtest.h>

namespace hapsim {
namespace {

TEST(DeviceProfile, EveryBuiltinIsUsable) {
  const auto& profiles = builtin_device_profiles();
  ASSERT_GE(profiles.size(), 5u);
  for (const DeviceProfile& p : profiles) {
    SCOPED_TRACE(p.name);
    EXPECT_EQ(&device_profile(p.name), &p);
    EXPECT_FALSE(p.display_name.empty());
    EXPECT_FALSE(p.source.empty());
    EXPECT_TRUE(std::isfinite(p.max_force_n) && p.max_force_n >= 0.0);
    EXPECT_TRUE(p.max_force_n > 0.0 || p.max_finger_force_n > 0.0) << "renders no force at all";
    EXPECT_LE(p.max_continuous_force_n, std::max(p.max_force_n, p.max_finger_force_n));
    EXPECT_GT(p.max_stiffness_n_per_m, 0.0);
    EXPECT_GE(p.finger_count, 0);
    EXPECT_LE(p.finger_count, kMaxFingers);
    EXPECT_EQ(p.finger_count > 0, p.max_finger_force_n > 0.0);
    EXPECT_TRUE((p.workspace_world.max() - p.workspace_world.min()).minCoeff() > 0.0);
    if (p.max_force_rate_n_per_s) {
      EXPECT_GT(*p.max_force_rate_n_per_s, 0.0);
    }
  }
}

TEST(DeviceProfile, ValuesFromTheSeedAndCsv) {
  EXPECT_DOUBLE_EQ(device_profile("touch").max_force_n, 3.3);
  EXPECT_DOUBLE_EQ(device_profile("touch").max_stiffness_n_per_m, 400.0);
  EXPECT_DOUBLE_EQ(device_profile("phantom_omni").max_stiffness_n_per_m, 700.0);
  EXPECT_DOUBLE_EQ(device_profile("omega3").max_force_n, 12.0);
  EXPECT_DOUBLE_EQ(device_profile("omega3").max_stiffness_n_per_m, 5000.0);
  EXPECT_DOUBLE_EQ(device_profile("falcon").max_force_n, 8.0);
  // Seed 001: "about 4N per fingertip", "designed for four fingers".
  const DeviceProfile& glove = device_profile("rutgers_master");
  EXPECT_EQ(glove.finger_count, 4);
  EXPECT_DOUBLE_EQ(glove.max_finger_force_n, 4.0);
  EXPECT_EQ(glove.max_force_n, 0.0);
  EXPECT_TRUE(glove.max_force_rate_n_per_s.has_value());
}

// The CHAI3D-derived profiles must agree with the project's data table, row by row.
TEST(DeviceProfile, Chai3dProfilesMatchTheDataTable) {
  const std::string csv_path = test::data_path("tissue_device_values.csv").string();
  std::ifstream in(csv_path);
  HAPSIM_SKIP_WITHOUT_DATA(in.is_open(), "no data table at " << csv_path);
  std::stringstream text;
  text << in.rdbuf();
  const std::string csv = text.str();
  // The numbers of the "value" column (third) of the row whose quantity starts with `key`.
  const auto numbers_of = [&](const std::string& key) {
    std::vector<double> numbers;
    const std::size_t at = csv.find("device," + key);
    EXPECT_NE(at, std::string::npos) << key;
    if (at == std::string::npos) {
      return numbers;
    }
    const std::string row = csv.substr(at, csv.find('\n', at) - at);
    const std::size_t c1 = row.find(',');
    const std::size_t c2 = row.find(',', c1 + 1);
    const std::string value = row.substr(c2 + 1, row.find(',', c2 + 1) - c2 - 1);
    const std::regex number(R"([0-9]+(\.[0-9]+)?)");
    for (auto it = std::sregex_iterator(value.begin(), value.end(), number);
         it != std::sregex_iterator(); ++it) {
      numbers.push_back(std::stod(it->str()));
    }
    return numbers;
  };
  const struct {
    const char* profile;
    const char* row;
  } cases[] = {{"touch", "CHAI3D default limits: Touch,"},
               {"phantom_omni", "CHAI3D default limits: PHANTOM Omni,"},
               {"omega3", "CHAI3D default limits: omega.3"},
               {"falcon", "CHAI3D default limits: Novint Falcon,"}};
  for (const auto& c : cases) {
    SCOPED_TRACE(c.profile);
    const DeviceProfile& p = device_profile(c.profile);
    // Value column: "<force> N; <stiffness> N/m; <damping> N s/m; [workspace radius] <r> m".
    const std::vector<double> n = numbers_of(c.row);
    ASSERT_EQ(n.size(), 4u);
    EXPECT_DOUBLE_EQ(p.max_force_n, n[0]);
    EXPECT_DOUBLE_EQ(p.max_stiffness_n_per_m, n[1]);
    EXPECT_DOUBLE_EQ(p.max_damping_n_s_per_m, n[2]);
    EXPECT_DOUBLE_EQ(p.workspace_world.max().x(), n[3]);  // cube bounding the radius
    EXPECT_DOUBLE_EQ(p.workspace_world.min().x(), -n[3]);
  }
}

TEST(DeviceProfile, UnknownNameListsTheKnownOnes) {
  try {
    (void)device_profile("phantom_premium");
    FAIL() << "expected hapsim::Error";
  } catch (const Error& e) {
    const std::string message = e.what();
    EXPECT_NE(message.find("'phantom_premium'"), std::string::npos) << message;
    for (const std::string& name : device_profile_names()) {
      EXPECT_NE(message.find(name), std::string::npos) << name << " missing in: " << message;
    }
  }
}

}  // namespace
}  // namespace hapsim
