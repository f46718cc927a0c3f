// Checks a gate runs on a sample's fixed-size arrays before trusting it: every value finite, every
// value within a bound. haptic path (no allocation)
#pragma once

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <iterator>

namespace hapsim::net {

template <std::size_t N>
[[nodiscard]] bool all_finite(const double (&values)[N]) noexcept {
  return std::all_of(std::begin(values), std::end(values),
                     [](double v) { return std::isfinite(v); });
}

template <std::size_t N>
[[nodiscard]] bool within(const double (&values)[N], double limit) noexcept {
  return std::all_of(std::begin(values), std::end(values),
                     [limit](double v) { return std::abs(v) <= limit; });
}

}  // namespace hapsim::net
