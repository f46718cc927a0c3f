// The distributed commands' network options: loopback unless --interface names another; a name
// that is not one and a --peer without an interface are each one line and exit 2, before anything
// is sent (serve and device; view --connect shares the options and the domain code); an interface
// named while CYCLONEDDS_URI is set is merged into the user's config.
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
}

TEST(NetworkOptions, AnInterfaceIsMergedWithTheUsersConfig) {
  // The user's own config (no interface of its own) with --interface and --peer added to it
  // (issue 32; they used to be refused together).
  const auto user = hapsim::test::write_file(
      "user-cyclonedds.xml",
      "<CycloneDDS><Domain id=\"any\"><General><AllowMulticast>false</AllowMulticast></General>"
      "<SharedMemory><Enable>false</Enable></SharedMemory></Domain></CycloneDDS>");
  const auto both = hapsim::test::run_hapsim_env(
      "env CYCLONEDDS_URI=file://" + user.string(),
      "serve " + kScene + " --interface lo --peer 127.0.0.2 --duration 0.2 --domain 82");
  EXPECT_EQ(both.exit_code, 0) << both.output;
  EXPECT_NE(both.output.find("user-cyclonedds.xml on interface lo, 1 peer(s)"), std::string::npos)
      << both.output;
}

TEST(NetworkOptions, PlainServeOffThisMachineNeedsInsecure) {
  const auto refused = run_without_uri("serve " + kScene + " --interface eth9 --duration 0.1");
  EXPECT_EQ(refused.exit_code, 2) << refused.output;
  EXPECT_NE(refused.output.find("--interface eth9: serving plain DDS off this machine needs "
                                "--insecure"),
            std::string::npos)
      << refused.output;
  const auto both = run_without_uri("serve " + kScene + " --secure /nonexistent --insecure");
  EXPECT_EQ(both.exit_code, 2) << both.output;
  EXPECT_NE(both.output.find("--insecure: --secure /nonexistent is given too"), std::string::npos)
      << both.output;
}

TEST(NetworkOptions, AnInterfaceNamedRunsOnItWithTheShippedConfig) {
  const auto served = run_without_uri("serve " + kScene + " --interface lo --duration 0.2");
  EXPECT_EQ(served.exit_code, 0) << served.output;
  EXPECT_NE(served.output.find("cyclonedds-loopback.xml on interface lo"), std::string::npos)
      << served.output;
}

}  // namespace
}  // namespace hapsim::net
