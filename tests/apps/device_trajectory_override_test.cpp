// `--device sim:FILE` plays FILE: a scene whose device names a trajectory CSV that is absent
// runs with another one (it demanded the scene's own file); without --device the absent file is
// still the load's one-line error, naming its JSON path.
#include "apps/hapsim_process.h"

#include <cstdlib>
#include <fstream>
#include <string>

#include <gtest/gtest.h>

namespace hapsim {
namespace {

TEST(DeviceTrajectoryOverride, SimFileDoesNotNeedTheScenesOwnTrajectory) {
  const auto scene = test::temp_path("override_scene.json");
  const auto other = test::temp_path("override_other.csv");
  {
    std::ofstream s(scene);
    s << R"({
  "format": "hapsim-scene/1",
  "world": { "name": "override" },
  "materials": { "bone": { "response": "proxy", "stiffness_n_per_m": 1000.0,
                           "max_penetration_m": 0.004, "max_force_n": 5.0 } },
  "bodies": [ { "name": "block", "type": "static",
                "geometry": { "box": { "half_extents_m": [0.02, 0.02, 0.01] } },
                "materials": "bone" } ],
  "tools": [ { "name": "tip", "radius_m": 0.002 } ],
  "device": { "type": "simulated", "profile": "omega3", "trajectory": "absent.csv" },
  "run": { "duration_s": 0.0, "dt_s": 0.001 }
})";
    std::ofstream t(other);
    t << "t,x,y,z,qw,qx,qy,qz\n0,0,0,0.02,1,0,0,0\n0.2,0,0,0.009,1,0,0,0\n";
  }
  const auto played =
      test::run_hapsim("run " + scene.string() + " --device sim:" + other.string() + " -q");
  EXPECT_EQ(played.exit_code, 0) << played.output;
  EXPECT_EQ(played.output.find("absent.csv"), std::string::npos) << played.output;

  const auto own = test::run_hapsim("run " + scene.string() + " -q");
  EXPECT_EQ(own.exit_code, 2) << own.output;
  EXPECT_NE(own.output.find("/device/trajectory: no such file"), std::string::npos) << own.output;

  // The viewer: its mouse and sim:FILE play no trajectory of the scene's.
  if (std::system("command -v xvfb-run > /dev/null 2>&1") != 0) {
    GTEST_SKIP() << "xvfb-run is missing: the viewer's half is not checked";
  }
  for (const std::string& device : {std::string("mouse"), "sim:" + other.string()}) {
    const auto viewed =
        test::run_hapsim_env("timeout 120 xvfb-run -a",
                             "view " + scene.string() + " --device " + device + " --duration 0.3");
    EXPECT_EQ(viewed.exit_code, 0) << device << ": " << viewed.output;
    EXPECT_EQ(viewed.output.find("absent.csv"), std::string::npos) << viewed.output;
  }
}

}  // namespace
}  // namespace hapsim
