// The shipped Cyclone config keeps every hapsim process on loopback (issue 12: "nothing is sent
// off loopback with the shipped config"): with it, Cyclone selects the interface `lo` alone, with
// multicast off, whatever other interfaces the machine has. Read from Cyclone's own trace of the
// configuration it chose.
#include "hapsim/net/participant.h"

#include "net/net_test_support.h"

#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

#include <gtest/gtest.h>

namespace hapsim::net {
namespace {

constexpr dds_domainid_t kDomain = 75;

TEST(LoopbackConfig, CycloneSelectsOnlyTheLoopbackInterfaceWithoutMulticast) {
  ASSERT_TRUE(test::on_loopback_config());
  const std::filesystem::path trace = std::filesystem::temp_directory_path() /
                                      ("hapsim_dds_trace_" + std::to_string(::getpid()) + ".log");
  std::filesystem::remove(trace);
  // The shipped file, plus a fragment that only turns on Cyclone's configuration trace.
  const std::string config = std::string("file://") + HAPSIM_DDS_CONFIG +
                             ",<Tracing><Category>config</Category><OutputFile>" + trace.string() +
                             "</OutputFile></Tracing>";
  const dds_entity_t domain = dds_create_domain(kDomain, config.c_str());
  ASSERT_GT(domain, 0) << dds_strretcode(domain);
  { Participant participant(kDomain, "loopback-check"); }
  dds_delete(domain);

  std::ifstream in(trace);
  ASSERT_TRUE(in) << trace;
  std::string selected;
  std::string line;
  bool multicast_off = false;
  while (std::getline(in, line)) {
    if (const auto at = line.find("selected interfaces: "); at != std::string::npos) {
      selected = line.substr(at + 21);
    }
    multicast_off |= line.find("General/AllowMulticast/#text: false") != std::string::npos;
  }
  std::filesystem::remove(trace);
  std::printf("cyclone selected interfaces: %s\n", selected.c_str());
  // "lo (index 1 priority 2)": one interface, and it is loopback.
  EXPECT_EQ(selected.rfind("lo (", 0), 0u) << selected;
  EXPECT_EQ(selected.find(','), std::string::npos) << selected;
  EXPECT_TRUE(multicast_off);
}

}  // namespace
}  // namespace hapsim::net
