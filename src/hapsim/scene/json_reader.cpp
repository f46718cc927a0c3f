#include "hapsim/scene/json_reader.h"

#include "hapsim/core/error.h"

#include <algorithm>
#include <cmath>
#include <sstream>

namespace hapsim {
namespace {

// JSON pointer escaping (RFC 6901) for keys that contain '/' or '~'.
std::string escape_key(const std::string& key) {
  std::string out;
  for (char c : key) {
    if (c == '~') {
      out += "~0";
    } else if (c == '/') {
      out += "~1";
    } else {
      out += c;
    }
  }
  return out;
}

}  // namespace

using Json = JsonReader::Json;

std::string JsonReader::type_name(const Json& j) {
  switch (j.type()) {
    case Json::value_t::null:
      return "null";
    case Json::value_t::object:
      return "an object";
    case Json::value_t::array:
      return "an array";
    case Json::value_t::string:
      return "a string";
    case Json::value_t::boolean:
      return "a boolean";
    case Json::value_t::number_integer:
    case Json::value_t::number_unsigned:
    case Json::value_t::number_float:
      return "a number";
    default:
      return "something else";
  }
}

std::string JsonReader::shown(const Json& j) {
  std::string s = j.dump();
  if (s.size() > 40) {
    s = s.substr(0, 37) + "...";
  }
  return s;
}

void JsonReader::fail(const std::string& ptr, const std::string& what) const {
  throw Error(file_.string() + ":" + (ptr.empty() ? "/" : ptr), what);
}

std::string JsonReader::at(const std::string& ptr, const std::string& key) {
  return ptr + "/" + escape_key(key);
}
std::string JsonReader::at(const std::string& ptr, std::size_t index) {
  return ptr + "/" + std::to_string(index);
}

const Json& JsonReader::object(const Json& j, const std::string& ptr,
                               const std::string& what) const {
  if (!j.is_object()) {
    fail(ptr, "expected " + what + " (a JSON object), got " + type_name(j));
  }
  return j;
}
const Json& JsonReader::array(const Json& j, const std::string& ptr,
                              const std::string& what) const {
  if (!j.is_array()) {
    fail(ptr, "expected " + what + " (a JSON array), got " + type_name(j));
  }
  return j;
}

void JsonReader::allow_keys(const Json& obj, const std::string& ptr,
                            std::initializer_list<const char*> allowed) const {
  for (const auto& item : obj.items()) {
    const std::string& key = item.key();
    if (std::none_of(allowed.begin(), allowed.end(), [&](const char* a) { return key == a; })) {
      std::string list;
      for (const char* a : allowed) {
        list += list.empty() ? "" : ", ";
        list += a;
      }
      std::string what = "unknown key '";
      what += key;
      what += "'; allowed here: ";
      what += list;
      fail(at(ptr, key), what);
    }
  }
}

const Json& JsonReader::required(const Json& obj, const std::string& ptr, const char* key) const {
  if (!obj.contains(key)) {
    fail(ptr, std::string("missing required key '") + key + "'");
  }
  return obj.at(key);
}

double JsonReader::number(const Json& j, const std::string& ptr, const std::string& unit) const {
  if (!j.is_number()) {
    fail(ptr, "expected a number" + (unit.empty() ? "" : " in " + unit) + ", got " + type_name(j) +
                  " " + shown(j));
  }
  const double v = j.get<double>();
  if (!std::isfinite(v)) {
    fail(ptr, "expected a finite number" + (unit.empty() ? "" : " in " + unit));
  }
  // A length beyond any scene (a body at 1e300 m squares to inf in every distance test).
  constexpr double kMaxLength_m = 1e6;
  if (unit == "m" && !(std::abs(v) <= kMaxLength_m)) {
    fail(ptr, "expected a length within 1e6 m, got " + shown(j));
  }
  return v;
}

double JsonReader::number_in(const Json& obj, const std::string& ptr, const char* key,
                             double fallback, double lo, double hi, const std::string& unit,
                             bool lo_open, bool inf_allowed) const {
  if (!obj.contains(key)) {
    return fallback;
  }
  const std::string p = at(ptr, key);
  const Json& j = obj.at(key);
  if (inf_allowed && j.is_string() && j.get<std::string>() == "inf") {
    return kInf;
  }
  const double v = number(j, p, unit);
  if (v < lo || (lo_open && v == lo) || v > hi) {
    std::ostringstream range;
    range << (lo_open ? "> " : ">= ") << lo;
    if (std::isfinite(hi)) {
      range << " and <= " << hi;
    }
    fail(p, "expected a number " + range.str() + (unit.empty() ? "" : " in " + unit) + ", got " +
                shown(j));
  }
  return v;
}

bool JsonReader::boolean(const Json& j, const std::string& ptr) const {
  if (!j.is_boolean()) {
    fail(ptr, "expected true or false, got " + shown(j));
  }
  return j.get<bool>();
}

std::string JsonReader::string(const Json& j, const std::string& ptr,
                               const std::string& what) const {
  if (!j.is_string()) {
    fail(ptr, "expected " + what + " (a string), got " + type_name(j));
  }
  return j.get<std::string>();
}

std::string JsonReader::nonempty_string(const Json& j, const std::string& ptr,
                                        const std::string& what) const {
  std::string s = string(j, ptr, what);
  if (s.empty()) {
    fail(ptr, "expected " + what + ", got an empty string");
  }
  return s;
}

std::string JsonReader::one_of(const Json& j, const std::string& ptr,
                               std::initializer_list<const char*> choices) const {
  std::string list;
  for (const char* c : choices) {
    list += (list.empty() ? "'" : ", '") + std::string(c) + "'";
  }
  if (j.is_string()) {
    std::string s = j.get<std::string>();
    for (const char* c : choices) {
      if (s == c) {
        return s;
      }
    }
  }
  fail(ptr, "expected one of " + list + ", got " + shown(j));
}

Vec3 JsonReader::vec3(const Json& j, const std::string& ptr, const std::string& unit) const {
  if (!j.is_array() || j.size() != 3) {
    fail(ptr, "expected [x, y, z] (3 numbers" + (unit.empty() ? "" : " in " + unit) + "), got " +
                  shown(j));
  }
  Vec3 v;
  for (std::size_t i = 0; i < 3; ++i) {
    v[static_cast<Eigen::Index>(i)] = number(j[i], at(ptr, i), unit);
  }
  return v;
}

Iso3 JsonReader::parse_pose(const Json& j, const std::string& ptr) const {
  object(j, ptr, "a pose");
  allow_keys(j, ptr, {"position_m", "rotation_deg", "quaternion_wxyz"});
  Iso3 X = Iso3::Identity();
  if (j.contains("position_m")) {
    X.translation() = vec3(j["position_m"], at(ptr, "position_m"), "m");
  }
  if (j.contains("rotation_deg") && j.contains("quaternion_wxyz")) {
    fail(ptr, "expected one of 'rotation_deg' or 'quaternion_wxyz', not both");
  }
  if (j.contains("rotation_deg")) {
    const Vec3 deg = vec3(j["rotation_deg"], at(ptr, "rotation_deg"), "degrees");
    const Vec3 rad = deg * (3.14159265358979323846 / 180.0);
    // Fixed-axis x, then y, then z: R = Rz * Ry * Rx.
    X.linear() =
        (Eigen::AngleAxisd(rad.z(), Vec3::UnitZ()) * Eigen::AngleAxisd(rad.y(), Vec3::UnitY()) *
         Eigen::AngleAxisd(rad.x(), Vec3::UnitX()))
            .toRotationMatrix();
  }
  if (j.contains("quaternion_wxyz")) {
    const std::string qp = at(ptr, "quaternion_wxyz");
    const Json& q = j["quaternion_wxyz"];
    if (!q.is_array() || q.size() != 4) {
      fail(qp, "expected [w, x, y, z], got " + shown(q));
    }
    Quat quat(number(q[0], at(qp, std::size_t{0}), ""), number(q[1], at(qp, 1), ""),
              number(q[2], at(qp, 2), ""), number(q[3], at(qp, 3), ""));
    if (std::abs(quat.norm() - 1.0) > 1e-6) {
      fail(qp, "expected a unit quaternion, got norm " + std::to_string(quat.norm()));
    }
    X.linear() = quat.normalized().toRotationMatrix();
  }
  return X;
}

}  // namespace hapsim
