#include "hapsim/geometry/body_part_size.h"

#include <cmath>
#include <cstdio>

namespace hapsim {
namespace {

bool plausible(double extent_m) {
  return extent_m >= kBodyPartMinExtentM && extent_m <= kBodyPartMaxExtentM;
}

// The plural name of a common unit of mesh files, or null.
const char* unit_name(double metres_per_unit) {
  constexpr struct {
    double scale;
    const char* name;
  } kUnits[] = {{1.0, "metres"}, {0.01, "centimetres"}, {0.001, "millimetres"}};
  for (const auto& u : kUnits) {
    if (std::abs(metres_per_unit - u.scale) <= 1e-9 * u.scale) {
      return u.name;
    }
  }
  return nullptr;
}

}  // namespace

std::optional<MeshScaleAdvice> check_body_part_size(double extent_m, double scale) {
  if (!(std::isfinite(extent_m) && extent_m > 0.0 && std::isfinite(scale) && scale > 0.0) ||
      plausible(extent_m)) {
    return std::nullopt;
  }
  MeshScaleAdvice a;
  a.extent_m = extent_m;
  a.scale = scale;
  a.too_large = extent_m > kBodyPartMaxExtentM;
  const double file_units = extent_m / scale;  // the extent in the file's own numbers
  // The likely mistakes first: too large, a file in millimetres (or centimetres) read as a larger
  // unit; too small, one in metres (or centimetres) read as a smaller one.
  constexpr double kSmallerUnits[] = {0.001, 0.01};
  constexpr double kLargerUnits[] = {1.0, 0.01};
  bool found = false;
  for (const double unit : a.too_large ? kSmallerUnits : kLargerUnits) {
    if ((a.too_large ? unit < scale : unit > scale) && plausible(file_units * unit)) {
      a.suggested_scale = unit;
      found = true;
      break;
    }
  }
  if (!found) {
    a.suggested_scale = scale * std::pow(10.0, std::round(std::log10(0.1 / extent_m)));
  }
  const char* read_as = unit_name(scale);
  const char* meant = unit_name(a.suggested_scale);
  if (read_as != nullptr && meant != nullptr) {
    a.likely_mistake = std::string(meant) + " read as " + read_as;
  }
  return a;
}

std::string format_length(double metres) {
  char text[64];
  if (std::abs(metres) >= 1.0) {
    std::snprintf(text, sizeof text, "%.4g m", metres);
  } else {
    std::snprintf(text, sizeof text, "%.4g mm", metres * 1e3);
  }
  return text;
}

std::string format_scale(double scale) {
  char text[64];
  std::snprintf(text, sizeof text, "%g", scale);
  return text;
}

std::string describe(const MeshScaleAdvice& a) {
  std::string s = "is " + format_length(a.extent_m) + " across at scale " + format_scale(a.scale) +
                  ": implausibly " + (a.too_large ? "large" : "small") + " for a body part (" +
                  format_length(kBodyPartMinExtentM) + " to " + format_length(kBodyPartMaxExtentM) +
                  "); ";
  if (!a.likely_mistake.empty()) {
    s += a.likely_mistake + "? Use \"scale\": ";
  } else {
    s += "use \"scale\": ";
  }
  return s + format_scale(a.suggested_scale);
}

}  // namespace hapsim
