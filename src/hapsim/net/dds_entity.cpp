#include "hapsim/net/dds_entity.h"

#include "hapsim/core/error.h"

#include <string>

namespace hapsim::net {

dds_return_t check_dds(dds_return_t rc, std::string_view what) {
  if (rc < 0) {
    throw Error("dds", std::string(what) + ": " + dds_strretcode(rc));
  }
  return rc;
}

}  // namespace hapsim::net
