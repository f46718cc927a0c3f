// The `realtime` block of `hapsim run --realtime --json` (knee and teleop scenes alike).
#pragma once

#include "hapsim/runtime/session.h"

#include <nlohmann/json.hpp>

namespace hapsim::app {

inline nlohmann::json realtime_json(const RealtimeSummary& rt) {
  return {{"rate_hz", rt.rate_hz},
          {"period_jitter_us",
           {{"p50", rt.period_jitter_us.p50},
            {"p99", rt.period_jitter_us.p99},
            {"max", rt.period_jitter_us.max}}},
          {"missed_deadlines", rt.missed_deadlines},
          {"scheduling", rt.realtime_priority ? "SCHED_FIFO" : "normal"},
          {"stall_events", rt.stall_events},
          {"ramp_cycles", rt.ramp_cycles},
          {"failed_steps", rt.failed_steps},
          {"dropped_records", rt.dropped_records}};
}

}  // namespace hapsim::app
