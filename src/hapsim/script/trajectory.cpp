#include "hapsim/script/trajectory.h"

#include "hapsim/core/atomic_file.h"
#include "hapsim/core/error.h"
#include "hapsim/core/text_file.h"

#include <algorithm>
#include <array>
#include <charconv>
#include <cmath>
#include <fstream>
#include <limits>
#include <sstream>
#include <system_error>

namespace hapsim {
namespace {

constexpr std::array<std::string_view, 8> kPoseColumns = {"t",  "x",  "y",  "z",
                                                          "qw", "qx", "qy", "qz"};
constexpr std::string_view kPoseHeader = "t,x,y,z,qw,qx,qy,qz";

std::string_view trim(std::string_view s) {
  const auto is_space = [](char c) { return c == ' ' || c == '\t' || c == '\r'; };
  while (!s.empty() && is_space(s.front())) {
    s.remove_prefix(1);
  }
  while (!s.empty() && is_space(s.back())) {
    s.remove_suffix(1);
  }
  return s;
}

// What one header column means.
enum class ColumnKind { kTime, kPos, kQuat, kFinger, kJoint, kSensor, kButtons };
struct Column {
  std::string name;
  ColumnKind kind = ColumnKind::kTime;
  int index = 0;  // axis (x,y,z / w,x,y,z) or finger / joint number
};

// A field of a line with its 1-based character column, for messages.
struct Field {
  std::string_view text;
  std::size_t char_column = 1;
};

std::vector<Field> split_fields(std::string_view line) {
  std::vector<Field> fields;
  std::size_t start = 0;
  while (true) {
    const std::size_t comma = line.find(',', start);
    const std::size_t end = comma == std::string_view::npos ? line.size() : comma;
    std::string_view raw = line.substr(start, end - start);
    std::size_t lead = 0;
    while (lead < raw.size() && (raw[lead] == ' ' || raw[lead] == '\t')) {
      ++lead;
    }
    fields.push_back({trim(raw), start + lead + 1});
    if (comma == std::string_view::npos) {
      break;
    }
    start = comma + 1;
  }
  return fields;
}

std::string location(std::string_view source, std::size_t line, std::size_t column) {
  return std::string(source) + ":" + std::to_string(line) + ":" + std::to_string(column);
}

// "f3" -> 3 when `prefix` is 'f'; -1 when the name is not of that form.
int indexed_name(std::string_view name, char prefix) {
  if (name.size() < 2 || name[0] != prefix) {
    return -1;
  }
  int value = -1;
  const auto [ptr, ec] = std::from_chars(name.data() + 1, name.data() + name.size(), value);
  if (ec != std::errc() || ptr != name.data() + name.size() ||
      (name.size() > 2 && name[1] == '0')) {
    return -1;
  }
  return value;
}

std::vector<Column> parse_header(std::string_view line, std::string_view source,
                                 std::size_t line_no, int& finger_count, int& joint_count,
                                 int& sensor_count, bool& has_buttons) {
  const std::vector<Field> fields = split_fields(line);
  std::vector<Column> columns;
  for (std::size_t i = 0; i < fields.size(); ++i) {
    const Field& f = fields[i];
    const std::string where = location(source, line_no, f.char_column);
    if (i < kPoseColumns.size()) {
      if (f.text != kPoseColumns[i]) {
        throw Error(where, "header column " + std::to_string(i + 1) + " is '" +
                               std::string(f.text) + "', expected '" +
                               std::string(kPoseColumns[i]) + "' (the header starts with '" +
                               std::string(kPoseHeader) + "')");
      }
      if (i == 0) {
        columns.push_back({"t", ColumnKind::kTime, 0});
      } else if (i < 4) {
        columns.push_back({std::string(f.text), ColumnKind::kPos, static_cast<int>(i - 1)});
      } else {
        columns.push_back({std::string(f.text), ColumnKind::kQuat, static_cast<int>(i - 4)});
      }
      continue;
    }
    const int finger = indexed_name(f.text, 'f');
    const int joint = indexed_name(f.text, 'j');
    const int sensor = indexed_name(f.text, 's');
    if (f.text == "buttons") {
      if (has_buttons) {
        throw Error(where, "column 'buttons' appears twice");
      }
      has_buttons = true;
      columns.push_back({"buttons", ColumnKind::kButtons, 0});
    } else if (finger >= 0) {
      if (finger != finger_count || finger >= kMaxFingers) {
        throw Error(where,
                    "column '" + std::string(f.text) + "': expected " +
                        (finger_count < kMaxFingers ? "'f" + std::to_string(finger_count) + "'"
                                                    : std::string("no more finger columns")) +
                        " (finger columns run f0.." + "f" + std::to_string(kMaxFingers - 1) +
                        " in order)");
      }
      ++finger_count;
      columns.push_back({std::string(f.text), ColumnKind::kFinger, finger});
    } else if (joint >= 0) {
      if (joint != joint_count || joint >= kMaxDeviceJoints) {
        throw Error(where,
                    "column '" + std::string(f.text) + "': expected " +
                        (joint_count < kMaxDeviceJoints ? "'j" + std::to_string(joint_count) + "'"
                                                        : std::string("no more joint columns")) +
                        " (joint columns run j0..j" + std::to_string(kMaxDeviceJoints - 1) +
                        " in order)");
      }
      ++joint_count;
      columns.push_back({std::string(f.text), ColumnKind::kJoint, joint});
    } else if (sensor >= 0) {
      if (sensor != sensor_count || sensor >= kMaxRawSensors) {
        throw Error(where,
                    "column '" + std::string(f.text) + "': expected " +
                        (sensor_count < kMaxRawSensors ? "'s" + std::to_string(sensor_count) + "'"
                                                       : std::string("no more sensor columns")) +
                        " (raw sensor columns run s0..s" + std::to_string(kMaxRawSensors - 1) +
                        " in order)");
      }
      ++sensor_count;
      columns.push_back({std::string(f.text), ColumnKind::kSensor, sensor});
    } else {
      throw Error(where, "unknown column '" + std::string(f.text) + "'; expected f0..f" +
                             std::to_string(kMaxFingers - 1) + " (finger angles), j0..j" +
                             std::to_string(kMaxDeviceJoints - 1) + " (joint angles), s0..s" +
                             std::to_string(kMaxRawSensors - 1) +
                             " (raw glove sensor counts) or buttons");
    }
  }
  if (fields.size() < kPoseColumns.size()) {
    // Named at the end of the line, where the missing column should have been.
    const std::size_t missing = fields.size();
    throw Error(location(source, line_no, line.size() + 1),
                "header ends after " + std::to_string(missing) + " columns, expected '" +
                    std::string(kPoseColumns[missing]) + "' next (the header starts with '" +
                    std::string(kPoseHeader) + "')");
  }
  return columns;
}

double parse_number(const Field& f, const Column& column, const std::string& where) {
  double value = 0.0;
  const char* first = f.text.data();
  const char* last = f.text.data() + f.text.size();
  if (!f.text.empty() && *first == '+') {
    ++first;  // from_chars rejects a leading '+', people write it
  }
  const auto [ptr, ec] = std::from_chars(first, last, value);
  if (f.text.empty() || ec != std::errc() || ptr != last) {
    throw Error(where, "column '" + column.name + "': expected a number, got '" +
                           std::string(f.text) + "'");
  }
  if (!std::isfinite(value)) {
    throw Error(where, "column '" + column.name + "': expected a finite number, got '" +
                           std::string(f.text) + "'");
  }
  return value;
}

std::uint32_t parse_buttons(const Field& f, const std::string& where) {
  std::uint32_t value = 0;
  const char* last = f.text.data() + f.text.size();
  const auto [ptr, ec] = std::from_chars(f.text.data(), last, value);
  if (f.text.empty() || ec != std::errc() || ptr != last) {
    throw Error(where,
                "column 'buttons': expected an unsigned integer (button bits, bit 0 = "
                "primary) up to 4294967295, got '" +
                    std::string(f.text) + "'");
  }
  return value;
}

// Checks a quaternion's norm and normalises it. One already unit to rounding is left untouched,
// so saving and re-loading a trajectory is bit-exact (dividing by 1 +- ulp would not be).
bool normalise_quat(Quat& q) {
  const double norm = q.norm();
  if (!std::isfinite(norm) || std::abs(norm - 1.0) > kQuatNormTolerance) {
    return false;
  }
  if (std::abs(norm - 1.0) > 8.0 * std::numeric_limits<double>::epsilon()) {
    q.coeffs() /= norm;
  }
  return true;
}

std::string format_double(double v) {
  std::array<char, 32> buf{};
  const auto [ptr, ec] = std::to_chars(buf.data(), buf.data() + buf.size(), v);
  (void)ec;  // 32 chars always suffice for the shortest round-trip form
  return std::string(buf.data(), ptr);
}

}  // namespace

DeviceInput Trajectory::sample_at(double time_s) const noexcept {
  // upper_bound: the first sample strictly later than time_s, so a query exactly at a sample
  // time lands at the start of that sample's segment (weight 0) and returns it bit-exactly.
  const auto later = std::upper_bound(samples.begin(), samples.end(), time_s,
                                      [](double t, const DeviceInput& s) { return t < s.time_s; });
  DeviceInput out;
  if (later == samples.begin()) {
    out = samples.front();
  } else if (later == samples.end() || (later - 1)->time_s == time_s) {
    out = *(later - 1);  // at a sample: returned as stored (a + 0*(b-a) would turn -0 into +0)
  } else {
    const DeviceInput& a = *(later - 1);
    const DeviceInput& b = *later;
    const double alpha = (time_s - a.time_s) / (b.time_s - a.time_s);
    out = a;
    out.p_world = a.p_world + alpha * (b.p_world - a.p_world);
    // Slerp of unit quaternions is unit to rounding; not renormalised so weight 0 stays exact.
    out.q_world = a.q_world.slerp(alpha, b.q_world);
    for (int i = 0; i < finger_count; ++i) {
      out.finger_rad[i] = a.finger_rad[i] + alpha * (b.finger_rad[i] - a.finger_rad[i]);
    }
    for (int i = 0; i < joint_count; ++i) {
      out.joint_rad[i] = a.joint_rad[i] + alpha * (b.joint_rad[i] - a.joint_rad[i]);
    }
  }
  out.time_s = time_s;
  return out;
}

Trajectory make_trajectory(std::vector<DeviceInput> samples, int finger_count, int joint_count,
                           std::string_view where) {
  const std::string w(where);
  if (samples.empty()) {
    throw Error(w, "trajectory has no samples; expected at least one");
  }
  if (finger_count < 0 || finger_count > kMaxFingers) {
    throw Error(w, "finger count " + std::to_string(finger_count) + ", expected 0.." +
                       std::to_string(kMaxFingers));
  }
  if (joint_count < 0 || joint_count > kMaxDeviceJoints) {
    throw Error(w, "joint count " + std::to_string(joint_count) + ", expected 0.." +
                       std::to_string(kMaxDeviceJoints));
  }
  for (std::size_t i = 0; i < samples.size(); ++i) {
    DeviceInput& s = samples[i];
    const std::string at = w + ": sample " + std::to_string(i);
    bool finite = std::isfinite(s.time_s) && s.p_world.allFinite();
    for (int k = 0; k < finger_count; ++k) {
      finite = finite && std::isfinite(s.finger_rad[k]);
    }
    for (int k = 0; k < joint_count; ++k) {
      finite = finite && std::isfinite(s.joint_rad[k]);
    }
    if (!finite) {
      throw Error(at, "non-finite time, position or angle; expected finite values");
    }
    if (!normalise_quat(s.q_world)) {
      throw Error(at, "quaternion norm " + format_double(s.q_world.norm()) +
                          ", expected a unit quaternion (w, x, y, z)");
    }
    if (i > 0 && !(s.time_s > samples[i - 1].time_s)) {
      throw Error(at, "time " + format_double(s.time_s) + " s is not after the previous sample's " +
                          format_double(samples[i - 1].time_s) +
                          " s; times must strictly increase");
    }
    // Unused slots are zeroed so recordings of a played-back trajectory are reproducible.
    s.finger_count = finger_count;
    s.joint_count = joint_count;
    std::fill(s.finger_rad.begin() + finger_count, s.finger_rad.end(), 0.0);
    std::fill(s.joint_rad.begin() + joint_count, s.joint_rad.end(), 0.0);
    s.healthy = true;
  }
  Trajectory t;
  t.samples = std::move(samples);
  t.finger_count = finger_count;
  t.joint_count = joint_count;
  t.has_buttons = std::any_of(t.samples.begin(), t.samples.end(),
                              [](const DeviceInput& s) { return s.buttons != 0; });
  return t;
}

Trajectory parse_trajectory_csv(std::string_view text, std::string_view source_name) {
  Trajectory traj;
  std::vector<Column> columns;
  bool have_header = false;
  double position_scale = 1.0;  // `# units: mm` -> 1e-3
  std::size_t line_no = 0;
  std::size_t pos = 0;
  while (pos < text.size()) {
    const std::size_t nl = text.find('\n', pos);
    const std::size_t end = nl == std::string_view::npos ? text.size() : nl;
    std::string_view line = text.substr(pos, end - pos);
    pos = end + 1;
    ++line_no;
    if (!line.empty() && line.back() == '\r') {
      line.remove_suffix(1);
    }
    const std::string_view content = trim(line);
    if (content.empty()) {
      continue;
    }
    if (content.front() == '#') {
      std::string_view comment = trim(content.substr(1));
      if (comment.substr(0, 6) == "units:") {
        const std::string_view unit = trim(comment.substr(6));
        const std::string where = location(source_name, line_no, 1);
        if (have_header) {
          throw Error(where, "'# units:' must come before the header line");
        }
        if (unit == "m") {
          position_scale = 1.0;
        } else if (unit == "mm") {
          position_scale = 1e-3;
        } else {
          throw Error(where, "unknown unit '" + std::string(unit) + "', expected 'm' or 'mm'");
        }
      }
      continue;
    }
    if (!have_header) {
      columns = parse_header(line, source_name, line_no, traj.finger_count, traj.joint_count,
                             traj.sensor_count, traj.has_buttons);
      if (traj.sensor_count > 0 && traj.joint_count > 0) {
        throw Error(location(source_name, line_no, 1),
                    "a row carries either joint angles j0.. or raw sensor counts s0.., not both");
      }
      have_header = true;
      continue;
    }
    const std::vector<Field> fields = split_fields(line);
    if (fields.size() != columns.size()) {
      const std::size_t col =
          fields.size() > columns.size() ? fields[columns.size()].char_column : line.size() + 1;
      throw Error(location(source_name, line_no, col),
                  "row has " + std::to_string(fields.size()) + " fields, expected " +
                      std::to_string(columns.size()) + " as in the header");
    }
    DeviceInput s;
    s.finger_count = traj.finger_count;
    s.joint_count = traj.joint_count;
    double q[4] = {0, 0, 0, 0};  // w, x, y, z
    for (std::size_t i = 0; i < fields.size(); ++i) {
      const Column& c = columns[i];
      const std::string where = location(source_name, line_no, fields[i].char_column);
      if (c.kind == ColumnKind::kButtons) {
        s.buttons = parse_buttons(fields[i], where);
        continue;
      }
      const double v = parse_number(fields[i], c, where);
      switch (c.kind) {
        case ColumnKind::kTime:
          s.time_s = v;
          break;
        case ColumnKind::kPos:
          s.p_world[c.index] = v * position_scale;
          break;
        case ColumnKind::kQuat:
          q[c.index] = v;
          break;
        case ColumnKind::kFinger:
          s.finger_rad[static_cast<std::size_t>(c.index)] = v;
          break;
        case ColumnKind::kJoint:
          s.joint_rad[static_cast<std::size_t>(c.index)] = v;
          break;
        case ColumnKind::kSensor:
          traj.sensor_counts.push_back(v);  // columns come in order s0, s1, ...
          break;
        case ColumnKind::kButtons:
          break;
      }
    }
    s.q_world = Quat(q[0], q[1], q[2], q[3]);
    if (!normalise_quat(s.q_world)) {
      throw Error(location(source_name, line_no, fields[4].char_column),
                  "quaternion (qw,qx,qy,qz) has norm " + format_double(s.q_world.norm()) +
                      ", expected a unit quaternion (norm within " +
                      format_double(kQuatNormTolerance) + " of 1)");
    }
    if (!traj.samples.empty() && !(s.time_s > traj.samples.back().time_s)) {
      throw Error(location(source_name, line_no, fields[0].char_column),
                  "time " + format_double(s.time_s) + " is not greater than the previous row's " +
                      format_double(traj.samples.back().time_s) + "; times must strictly increase");
    }
    traj.samples.push_back(s);
  }
  const std::string where_file(source_name);
  if (!have_header) {
    throw Error(where_file, "no header: expected a first line '" + std::string(kPoseHeader) +
                                "' (optionally f0..f4, j0..jN, buttons) and data rows");
  }
  if (traj.samples.empty()) {
    throw Error(where_file, "no data rows after the header; expected at least one sample");
  }
  return traj;
}

Trajectory load_trajectory_csv(const std::filesystem::path& path) {
  // An hour at 1 kHz with five fingers is about 400 MB of text.
  constexpr std::size_t kMaxTrajectoryBytes = std::size_t{1} << 30;
  return parse_trajectory_csv(read_text_file(path, kMaxTrajectoryBytes, "trajectory CSV"),
                              path.string());
}

std::string format_trajectory_csv(const Trajectory& trajectory) {
  std::string out = "# units: m\n";  // SI; angles are radians
  out += kPoseHeader;
  for (int i = 0; i < trajectory.finger_count; ++i) {
    out += ",f" + std::to_string(i);
  }
  for (int i = 0; i < trajectory.joint_count; ++i) {
    out += ",j" + std::to_string(i);
  }
  for (int i = 0; i < trajectory.sensor_count; ++i) {
    out += ",s" + std::to_string(i);
  }
  if (trajectory.has_buttons) {
    out += ",buttons";
  }
  out += '\n';
  for (std::size_t row = 0; row < trajectory.samples.size(); ++row) {
    const DeviceInput& s = trajectory.samples[row];
    out += format_double(s.time_s);
    for (int k = 0; k < 3; ++k) {
      out += ',' + format_double(s.p_world[k]);
    }
    for (double c : {s.q_world.w(), s.q_world.x(), s.q_world.y(), s.q_world.z()}) {
      out += ',' + format_double(c);
    }
    for (int i = 0; i < trajectory.finger_count; ++i) {
      out += ',' + format_double(s.finger_rad[static_cast<std::size_t>(i)]);
    }
    for (int i = 0; i < trajectory.joint_count; ++i) {
      out += ',' + format_double(s.joint_rad[static_cast<std::size_t>(i)]);
    }
    for (const double c : trajectory.sensors(row)) {
      out += ',' + format_double(c);
    }
    if (trajectory.has_buttons) {
      out += ',' + std::to_string(s.buttons);
    }
    out += '\n';
  }
  return out;
}

void save_trajectory_csv(const Trajectory& trajectory, const std::filesystem::path& path) {
  write_file_atomically(path, format_trajectory_csv(trajectory));
}

}  // namespace hapsim
