#include "hapsim/net/link_shim_spec.h"

#include "hapsim/core/error.h"

#include <charconv>
#include <cmath>
#include <string>

namespace hapsim::net {

namespace {

double number(std::string_view key, std::string_view text, double lo, double hi,
              std::string_view option) {
  double value = 0.0;
  const auto [end, ec] = std::from_chars(text.data(), text.data() + text.size(), value);
  if (ec != std::errc() || end != text.data() + text.size() || !std::isfinite(value) ||
      value < lo || value > hi) {
    throw Error(std::string(option), std::string(key) + "=" + std::string(text) +
                                         ": expected a number from " + std::to_string(lo) + " to " +
                                         std::to_string(hi));
  }
  return value;
}

}  // namespace

LinkShimOptions parse_link_shim(std::string_view spec, std::string_view option) {
  LinkShimOptions o;
  while (!spec.empty()) {
    const std::size_t comma = spec.find(',');
    const std::string_view pair = spec.substr(0, comma);
    spec = comma == std::string_view::npos ? std::string_view{} : spec.substr(comma + 1);
    const std::size_t eq = pair.find('=');
    if (eq == std::string_view::npos) {
      throw Error(std::string(option),
                  "'" + std::string(pair) + "': expected KEY=VALUE (e.g. delay_ms=20,loss=0.1)");
    }
    const std::string_view key = pair.substr(0, eq);
    const std::string_view value = pair.substr(eq + 1);
    if (key == "delay_ms") {
      o.delay_s = 1e-3 * number(key, value, 0.0, 10'000.0, option);
    } else if (key == "jitter_ms") {
      o.jitter_s = 1e-3 * number(key, value, 0.0, 10'000.0, option);
    } else if (key == "loss") {
      o.loss = number(key, value, 0.0, 1.0, option);
    } else if (key == "burst_enter") {
      o.burst_enter = number(key, value, 0.0, 1.0, option);
    } else if (key == "burst_exit") {
      o.burst_exit = number(key, value, 0.0, 1.0, option);
    } else if (key == "outage_at_s") {
      o.outage_start_s = number(key, value, 0.0, 1e6, option);
    } else if (key == "outage_s") {
      o.outage_s = number(key, value, 0.0, 1e6, option);
    } else if (key == "seed") {
      o.seed = static_cast<std::uint64_t>(number(key, value, 0.0, 1e15, option));
    } else if (key == "ordered") {
      o.keep_order = number(key, value, 0.0, 1.0, option) != 0.0;
    } else {
      throw Error(std::string(option),
                  "unknown key '" + std::string(key) +
                      "' (delay_ms, jitter_ms, loss, burst_enter, burst_exit, outage_at_s, "
                      "outage_s, seed, ordered)");
    }
  }
  return o;
}

}  // namespace hapsim::net
