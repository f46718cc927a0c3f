// The network options every distributed command takes (serve, device, view --connect, watch,
// control): the session (a DDS partition), the domain, and — only when asked — an interface other
// than loopback with the unicast peers to reach through it, and a secure session's key directory
// (`--secure DIR` or HAPSIM_SECURE_DIR, docs/security.md) with the identity to join as.
#pragma once

#include "shipped_files.h"

#include "hapsim/core/error.h"
#include "hapsim/net/dds_domain.h"
#include "hapsim/net/security_config.h"
#include "hapsim/net/security_key_dir.h"

#include <CLI/CLI.hpp>

#include <string>
#include <vector>

namespace hapsim::app {

struct DdsOptions {
  std::string session = "default";
  int domain = 0;
  std::string interface;
  std::vector<std::string> peers;
  std::string secure_dir;  ///< empty: plain DDS
  std::string identity;    ///< empty: the role's default (net::default_identity)
  net::SecurityRole role = net::SecurityRole::kViewer;

  [[nodiscard]] bool secure() const { return !secure_dir.empty(); }
  /// The identity this process joins as (only with --secure).
  [[nodiscard]] std::string identity_name() const {
    return identity.empty() ? net::default_identity(role, secure_dir) : identity;
  }
  /// The network, with the checked security configuration when --secure is given (throws
  /// hapsim::Error naming the file and what is wrong).
  [[nodiscard]] net::DdsNetwork network() const {
    net::DdsNetwork n{interface, peers, {}, {}};
    if (secure()) {
      if (domain > 230) {
        throw Error("--domain", std::to_string(domain) +
                                    ": a secure session's governance covers domains 0-230");
      }
      const std::string name = identity_name();
      n.security = net::cyclone_security_xml(secure_dir, name, session);
      n.security_label = "identity " + name + " of " + secure_dir;
    }
    return n;
  }
};

/// `role`: what this command is in a secure session (its default identity).
inline void add_dds_options(CLI::App* cmd, DdsOptions& o, net::SecurityRole role) {
  o.role = role;
  cmd->add_option("--session", o.session,
                  "Session name: a DDS partition, so sessions never see each other (default "
                  "'default')");
  cmd->add_option("--domain", o.domain, "DDS domain id (default 0)")->check(CLI::Range(0, 232));
  cmd->add_option("--interface", o.interface,
                  "Network interface to use instead of loopback (e.g. eth0); default: loopback "
                  "only (config/cyclonedds-loopback.xml)");
  cmd->add_option("--peer", o.peers,
                  "With --interface: a host to discover (address or name; repeat for each)");
  cmd->add_option("--secure", o.secure_dir,
                  "DDS Security with the keys in DIR (hapsim keys init; docs/security.md): "
                  "authenticated, access-controlled, encrypted")
      ->envname("HAPSIM_SECURE_DIR");
  cmd->add_option("--identity", o.identity,
                  std::string("With --secure: the identity to join as (default ") +
                      (role == net::SecurityRole::kDevice
                           ? "this host's name if DIR has it, else 'device'"
                           : std::string("'") + std::string(net::role_name(role)) + "'") +
                      ")");
}

}  // namespace hapsim::app
