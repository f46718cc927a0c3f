#include "hapsim/net/dds_domain.h"

#include "hapsim/core/error.h"

#include <cstdlib>
#include <system_error>

namespace hapsim::net {

DdsDomain::DdsDomain(dds_domainid_t domain, const std::filesystem::path& default_config) {
  if (const char* uri = std::getenv("CYCLONEDDS_URI"); uri != nullptr && *uri != '\0') {
    config_ = std::string("CYCLONEDDS_URI=") + uri;
    return;
  }
  std::error_code ec;
  if (!std::filesystem::is_regular_file(default_config, ec)) {
    throw Error(default_config.string(), "no such Cyclone DDS config (set CYCLONEDDS_URI)");
  }
  config_ = default_config.string();
  const std::string uri = "file://" + std::filesystem::absolute(default_config).string();
  domain_ = DdsEntity(
      check_dds(dds_create_domain(domain, uri.c_str()), "creating domain from " + config_));
}

}  // namespace hapsim::net
