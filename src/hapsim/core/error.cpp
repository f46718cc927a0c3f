#include "hapsim/core/error.h"

#include <utility>

namespace hapsim {

Error::Error(std::string where, const std::string& what)
    : std::runtime_error(where.empty() ? what : where + ": " + what),
      where_(std::move(where)),
      detail_(what) {}

}  // namespace hapsim
