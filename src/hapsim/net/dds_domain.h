// Which Cyclone configuration a process's domain runs with: CYCLONEDDS_URI when the user set it,
// else the shipped loopback-only config (config/cyclonedds-loopback.xml), so a hapsim command
// never multicasts on the machine's real interface unless told to (issue 12).
#pragma once

#include "hapsim/net/dds_entity.h"

#include <filesystem>
#include <string>
#include <vector>

namespace hapsim::net {

/// Where the network goes instead of loopback (`--interface`, `--peer`): the shipped config with
/// this interface and these unicast peers (besides 127.0.0.1, for processes on this machine) —
/// or, when CYCLONEDDS_URI is set, the user's config with this interface and these peers added.
/// `security`: a <Security> fragment (net/security_config.h) appended last; empty: plain DDS.
struct DdsNetwork {
  std::string interface;  ///< empty: loopback only
  std::vector<std::string> peers;
  std::string security;
  std::string security_label;  ///< for the report, e.g. "identity serve of /keys"
};

class DdsDomain {
 public:
  /// Creates `domain` from `default_config` unless CYCLONEDDS_URI is set (then from the user's
  /// config, with `network`'s interface, peers and security merged after it: Cyclone reads a
  /// comma-separated list of files and XML fragments in order). Create before any participant of
  /// the domain. Throws hapsim::Error naming the file when it is missing or Cyclone refuses it.
  DdsDomain(dds_domainid_t domain, const std::filesystem::path& default_config,
            const DdsNetwork& network = {});

  /// "CYCLONEDDS_URI=…" or the file used, for the command's report.
  [[nodiscard]] const std::string& config() const noexcept { return config_; }
  /// Whether the domain runs DDS Security.
  [[nodiscard]] bool secure() const noexcept { return secure_; }

 private:
  DdsEntity domain_;
  std::string config_;
  bool secure_ = false;
};

}  // namespace hapsim::net
