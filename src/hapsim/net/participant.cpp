#include "hapsim/net/participant.h"

#include "hapsim/core/error.h"
#include "hapsim/net/dds_qos.h"

#include <algorithm>

namespace hapsim::net {

std::string session_partition(std::string_view session) {
  const bool ok = !session.empty() && session.size() <= 64 &&
                  std::all_of(session.begin(), session.end(), [](char c) {
                    return (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') ||
                           (c >= '0' && c <= '9') || c == '_' || c == '-';
                  });
  if (!ok) {
    throw Error("--session", "'" + std::string(session) +
                                 "' is not a session name: 1-64 characters of A-Z a-z 0-9 _ -");
  }
  return "hapsim." + std::string(session);
}

Participant::Participant(dds_domainid_t domain, std::string_view session)
    : partition_(session_partition(session)) {
  participant_ = DdsEntity(check_dds(dds_create_participant(domain, nullptr, nullptr),
                                     "creating a participant in domain " + std::to_string(domain)));
  Qos qos;
  dds_qset_partition1(qos.get(), partition_.c_str());
  publisher_ = DdsEntity(check_dds(dds_create_publisher(participant_.get(), qos.get(), nullptr),
                                   "creating the publisher"));
  subscriber_ = DdsEntity(check_dds(dds_create_subscriber(participant_.get(), qos.get(), nullptr),
                                    "creating the subscriber"));
}

}  // namespace hapsim::net
