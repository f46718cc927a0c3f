#include "hapsim/net/sample_verdict.h"

namespace hapsim::net {

const char* verdict_name(SampleVerdict verdict) noexcept {
  switch (verdict) {
    case SampleVerdict::kAccepted:
      return "accepted";
    case SampleVerdict::kMalformed:
      return "malformed";
    case SampleVerdict::kOutOfRange:
      return "out of range";
    case SampleVerdict::kOtherScene:
      return "other scene";
    case SampleVerdict::kOtherDevice:
      return "other device";
    case SampleVerdict::kOutOfOrder:
      return "out of order";
    case SampleVerdict::kStale:
      return "stale";
    case SampleVerdict::kOtherHost:
      return "other host";
  }
  return "?";
}

}  // namespace hapsim::net
