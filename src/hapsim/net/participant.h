// One DDS participant in one session: a domain participant plus the publisher and subscriber
// every writer and reader of hapsim hangs off. A session (`--session NAME`) is a DDS partition,
// so two trainees on one network and domain never see each other's samples (issue 12).
#pragma once

#include "hapsim/net/dds_entity.h"

#include <string>
#include <string_view>

namespace hapsim::net {

/// Domain ids are 0..232 in DDSI's port mapping.
inline constexpr dds_domainid_t kDefaultDomain = 0;

/// "hapsim.NAME": the DDS partition of session NAME. Throws hapsim::Error("--session", …) unless
/// NAME is 1-64 characters of [A-Za-z0-9_-] (partition names treat '*' and '?' as wildcards and
/// '.' separates levels: a session must match only itself).
[[nodiscard]] std::string session_partition(std::string_view session);

class Participant {
 public:
  /// Joins `domain` in `session`. Throws hapsim::Error naming Cyclone's reason on failure.
  Participant(dds_domainid_t domain, std::string_view session);

  [[nodiscard]] dds_entity_t participant() const noexcept { return participant_.get(); }
  [[nodiscard]] dds_entity_t publisher() const noexcept { return publisher_.get(); }
  [[nodiscard]] dds_entity_t subscriber() const noexcept { return subscriber_.get(); }
  [[nodiscard]] const std::string& partition() const noexcept { return partition_; }

 private:
  std::string partition_;
  // Declared first so it is deleted last (deleting it deletes its children anyway).
  DdsEntity participant_;
  DdsEntity publisher_;
  DdsEntity subscriber_;
};

}  // namespace hapsim::net
