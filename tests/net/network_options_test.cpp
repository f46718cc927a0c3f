// The distributed commands' network options: loopback unless --interface names another; a name
// that is not one, a --peer without an interface, and a choice made both in CYCLONEDDS_URI and on
// the command line are each one line and exit 2, before anything is sent (serve and device;
// view --connect shares the options and the domain code).
#include "apps/hapsim_process.h"

#include <gtest/gtest.h>

namespace hapsim::net {
namespace {

const std::string kScene = std::string(HAPSIM_SOURCE_DIR) + "/scenes/knee_procedural.json";

// `hapsim ARGS` with CYCLONEDDS_URI unset (the commands' own default then applies).
hapsim::test::RunResult run_without_uri(const std::string& args) {
  return hapsim::test::run_hapsim_env("env -u CYCLONEDDS_URI", args);
}

TEST(NetworkOptions, BadChoicesAreOneLineAndExitTwo) {
  // (view --connect takes the same options through the same code, inside its window.)
  for (const std::string& command : {std::string("serve ") + kScene, std::string("device")}) {
    const auto bad_name = run_without_uri(command + " --interface 'lo\"/><x' --duration 0.1");
    EXPECT_EQ(bad_name.exit_code, 2) << bad_name.output;
    EXPECT_NE(bad_name.output.find("--interface: 'lo\"/><x' is not an interface name"),
              std::string::npos)
        << bad_name.output;
    const auto peer_alone = run_without_uri(command + " --peer 10.0.0.2 --duration 0.1");
    EXPECT_EQ(peer_alone.exit_code, 2) << peer_alone.output;
    EXPECT_NE(peer_alone.output.find("--peer: give --interface too"), std::string::npos);
  }
  // A link shim is checked before anything starts.
  for (const std::string& command : {std::string("serve ") + kScene, std::string("device")}) {
    const auto bad_shim = hapsim::test::run_hapsim(command + " --link-shim delay_ms=20,latency=3");
    EXPECT_EQ(bad_shim.exit_code, 2) << bad_shim.output;
    EXPECT_NE(bad_shim.output.find("--link-shim: unknown key 'latency'"), std::string::npos)
        << bad_shim.output;
  }
  // ctest sets CYCLONEDDS_URI: a second choice on the command line is refused, not merged.
  const auto both = hapsim::test::run_hapsim("serve " + kScene + " --interface lo --duration 0.1");
  EXPECT_EQ(both.exit_code, 2) << both.output;
  EXPECT_NE(both.output.find("CYCLONEDDS_URI is set too"), std::string::npos) << both.output;
}

TEST(NetworkOptions, AnInterfaceNamedRunsOnItWithTheShippedConfig) {
  const auto served = run_without_uri("serve " + kScene + " --interface lo --duration 0.2");
  EXPECT_EQ(served.exit_code, 0) << served.output;
  EXPECT_NE(served.output.find("cyclonedds-loopback.xml on interface lo"), std::string::npos)
      << served.output;
}

}  // namespace
}  // namespace hapsim::net
