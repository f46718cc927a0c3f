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
/// this interface and these unicast peers (besides 127.0.0.1, for processes on this machine).
struct DdsNetwork {
  std::string interface;  ///< empty: loopback only
  std::vector<std::string> peers;
};

class DdsDomain {
 public:
  /// Creates `domain` from `default_config` unless CYCLONEDDS_URI is set (then Cyclone reads it
  /// when the first participant joins). Create before any participant of the domain. Throws
  /// hapsim::Error naming the file when it is missing or Cyclone refuses it.
  DdsDomain(dds_domainid_t domain, const std::filesystem::path& default_config,
            const DdsNetwork& network = {});

  /// "CYCLONEDDS_URI=…" or the file used, for the command's report.
  [[nodiscard]] const std::string& config() const noexcept { return config_; }

 private:
  DdsEntity domain_;
  std::string config_;
};

}  // namespace hapsim::net
