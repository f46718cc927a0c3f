// The network options every distributed command takes (serve, device, view --connect): the
// session (a DDS partition), the domain, and — only when asked — an interface other than loopback
// with the unicast peers to reach through it.
#pragma once

#include "hapsim/net/dds_domain.h"

#include <CLI/CLI.hpp>

#include <string>
#include <vector>

namespace hapsim::app {

struct DdsOptions {
  std::string session = "default";
  int domain = 0;
  std::string interface;
  std::vector<std::string> peers;

  [[nodiscard]] net::DdsNetwork network() const { return {interface, peers}; }
};

inline void add_dds_options(CLI::App* cmd, DdsOptions& o) {
  cmd->add_option("--session", o.session,
                  "Session name: a DDS partition, so sessions never see each other (default "
                  "'default')");
  cmd->add_option("--domain", o.domain, "DDS domain id (default 0)")->check(CLI::Range(0, 232));
  cmd->add_option("--interface", o.interface,
                  "Network interface to use instead of loopback (e.g. eth0); default: loopback "
                  "only (config/cyclonedds-loopback.xml)");
  cmd->add_option("--peer", o.peers,
                  "With --interface: a host to discover (address or name; repeat for each)");
}

}  // namespace hapsim::app
