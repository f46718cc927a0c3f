#include "hapsim/device/plugin_device.h"

#include "hapsim/core/error.h"

#include <dlfcn.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <iterator>
#include <utility>

namespace hapsim {
namespace {

// A driver's text on one line (hapsim's errors are one line), at most `max` characters.
std::string one_line(std::string_view text, std::size_t max = 200) {
  std::string out;
  for (const char c : text.substr(0, max)) {
    out += (c == '\n' || c == '\r' || c == '\t') ? ' ' : c;
  }
  while (!out.empty() && out.back() == ' ') {
    out.pop_back();
  }
  if (text.size() > max) {
    out += "...";
  }
  return out;
}

// A C string from a fixed buffer that may lack its NUL.
template <std::size_t N>
std::string_view bounded(const char (&text)[N]) {
  return {text, static_cast<std::size_t>(std::find(text, text + N, '\0') - text)};
}

template <std::size_t N>
bool all_finite(const double (&values)[N], std::size_t count = N) {
  return std::all_of(values, values + std::min(count, N),
                     [](double v) { return std::isfinite(v); });
}

// Which part of a driver's state cannot be trusted, or nullptr. haptic path
const char* state_problem(const hapsim_driver_state& s) {
  if (s.finger_count < 0 || s.finger_count > HAPSIM_DRIVER_MAX_FINGERS) {
    return "read_state() gave a finger_count out of range";
  }
  if (s.joint_count < 0 || s.joint_count > HAPSIM_DRIVER_MAX_JOINTS) {
    return "read_state() gave a joint_count out of range";
  }
  if (!std::isfinite(s.timestamp_s)) {
    return "read_state() gave a non-finite timestamp_s";
  }
  if (!all_finite(s.position_m)) {
    return "read_state() gave a non-finite position_m";
  }
  if (!all_finite(s.orientation_wxyz)) {
    return "read_state() gave a non-finite orientation_wxyz";
  }
  if (!all_finite(s.velocity_m_per_s)) {
    return "read_state() gave a non-finite velocity_m_per_s";
  }
  if (!all_finite(s.finger_rad, static_cast<std::size_t>(s.finger_count))) {
    return "read_state() gave a non-finite finger_rad";
  }
  if (!all_finite(s.joint_rad, static_cast<std::size_t>(s.joint_count))) {
    return "read_state() gave a non-finite joint_rad";
  }
  const double q_norm = std::sqrt(s.orientation_wxyz[0] * s.orientation_wxyz[0] +
                                  s.orientation_wxyz[1] * s.orientation_wxyz[1] +
                                  s.orientation_wxyz[2] * s.orientation_wxyz[2] +
                                  s.orientation_wxyz[3] * s.orientation_wxyz[3]);
  // Renormalising a slightly drifted quaternion is fine; a far-from-unit one is a wrong value.
  if (!(q_norm > 0.5 && q_norm < 1.5)) {
    return "read_state() gave an orientation_wxyz far from a unit quaternion";
  }
  return nullptr;
}

DeviceProfile profile_from_limits(const hapsim_driver_limits& l, std::string name,
                                  const std::filesystem::path& path) {
  const std::pair<const char*, double> numbers[] = {
      {"max_force_n", l.max_force_n},
      {"max_continuous_force_n", l.max_continuous_force_n},
      {"max_stiffness_n_per_m", l.max_stiffness_n_per_m},
      {"max_damping_n_s_per_m", l.max_damping_n_s_per_m},
      {"max_finger_force_n", l.max_finger_force_n},
      {"max_joint_torque_nm", l.max_joint_torque_nm},
      {"max_force_rate_n_per_s", l.max_force_rate_n_per_s},
  };
  for (const auto& [field, value] : numbers) {
    if (!(std::isfinite(value) && value >= 0.0)) {
      throw Error("plugin " + path.string(), std::string("rated_limits() gave ") + field + " = " +
                                                 std::to_string(value) +
                                                 " (expected a finite number >= 0)");
    }
  }
  for (int axis = 0; axis < 3; ++axis) {
    const double lo = l.workspace_min_m[axis];
    const double hi = l.workspace_max_m[axis];
    if (!(std::isfinite(lo) && std::isfinite(hi) && lo <= hi)) {
      throw Error("plugin " + path.string(), "rated_limits() gave a workspace axis " +
                                                 std::to_string(axis) + " from " +
                                                 std::to_string(lo) + " to " + std::to_string(hi) +
                                                 " m (expected finite, min <= max)");
    }
  }
  if (l.finger_count < 0 || l.finger_count > HAPSIM_DRIVER_MAX_FINGERS) {
    throw Error("plugin " + path.string(),
                "rated_limits() gave finger_count = " + std::to_string(l.finger_count) +
                    " (expected 0 to " + std::to_string(HAPSIM_DRIVER_MAX_FINGERS) + ")");
  }
  DeviceProfile p;
  p.name = std::move(name);
  p.display_name = one_line(bounded(l.model_name));
  if (p.display_name.empty()) {
    p.display_name = p.name;
  }
  p.max_force_n = l.max_force_n;
  p.max_continuous_force_n = l.max_continuous_force_n;
  p.max_stiffness_n_per_m = l.max_stiffness_n_per_m;
  p.max_damping_n_s_per_m = l.max_damping_n_s_per_m;
  p.workspace_world = Box3(Vec3(l.workspace_min_m[0], l.workspace_min_m[1], l.workspace_min_m[2]),
                           Vec3(l.workspace_max_m[0], l.workspace_max_m[1], l.workspace_max_m[2]));
  p.finger_count = l.finger_count;
  p.max_finger_force_n = l.max_finger_force_n;
  p.max_joint_torque_nm = l.max_joint_torque_nm;
  if (l.max_force_rate_n_per_s > 0.0) {
    p.max_force_rate_n_per_s = l.max_force_rate_n_per_s;
  }
  p.source = "device driver plugin " + path.string() + " (its rated_limits())";
  return p;
}

}  // namespace

struct PluginDevice::Library {
  explicit Library(void* h) : handle(h) {}
  ~Library() { dlclose(handle); }
  Library(const Library&) = delete;
  Library& operator=(const Library&) = delete;
  Library(Library&&) = delete;
  Library& operator=(Library&&) = delete;
  void* handle;
};

PluginDevice::PluginDevice(const std::filesystem::path& path, const std::string& config,
                           PluginDeviceOptions options)
    : path_(path), options_(options) {
  const std::string where = "plugin " + path.string();
  std::error_code ec;
  if (!std::filesystem::is_regular_file(path, ec)) {
    throw Error(where, "no such file");
  }
  if (!(options_.stale_after_s > 0.0 && options_.failed_after_s >= options_.stale_after_s)) {
    throw Error(where, "stale_after_s must be > 0 and failed_after_s >= stale_after_s");
  }
  // An absolute path: dlopen("name.so") would search the library path, not the current folder.
  // RTLD_NOW: an unresolved symbol fails here, in one line, not in the middle of a haptic cycle.
  const std::string absolute = std::filesystem::absolute(path, ec).string();
  dlerror();
  void* handle = dlopen(absolute.c_str(), RTLD_NOW | RTLD_LOCAL);
  if (handle == nullptr) {
    const char* raw = dlerror();
    std::string_view why = raw != nullptr ? raw : "unknown reason";
    if (why.starts_with(absolute + ": ")) {  // dlerror repeats the path
      why.remove_prefix(absolute.size() + 2);
    }
    throw Error(where, "not a shared object this process can load (" + one_line(why) + ")");
  }
  library_ = std::make_unique<Library>(handle);

  dlerror();
  void* symbol = dlsym(handle, HAPSIM_DEVICE_DRIVER_ENTRY);
  if (symbol == nullptr) {
    throw Error(where, "missing symbol " HAPSIM_DEVICE_DRIVER_ENTRY
                       " (a driver defines and exports it: see hapsim/device_driver.h)");
  }
  const auto entry = reinterpret_cast<hapsim_device_driver_entry_fn>(symbol);
  table_ = entry();
  if (table_ == nullptr) {
    throw Error(where, HAPSIM_DEVICE_DRIVER_ENTRY "() returned no driver table");
  }
  // Only abi_version is read before it matches: the rest of another version's table may differ.
  if (table_->abi_version != HAPSIM_DEVICE_DRIVER_ABI_VERSION) {
    throw Error(where, "ABI version " + std::to_string(table_->abi_version) + ", expected " +
                           std::to_string(HAPSIM_DEVICE_DRIVER_ABI_VERSION) +
                           " (rebuild the driver against this hapsim's hapsim/device_driver.h)");
  }
  if (table_->name == nullptr || table_->name[0] == '\0') {
    throw Error(where, "driver table has no name");
  }
  const std::pair<const char*, bool> functions[] = {
      {"open", table_->open != nullptr},
      {"read_state", table_->read_state != nullptr},
      {"write_command", table_->write_command != nullptr},
      {"rated_limits", table_->rated_limits != nullptr},
      {"health", table_->health != nullptr},
      {"close", table_->close != nullptr},
  };
  for (const auto& [function, present] : functions) {
    if (!present) {
      throw Error(where, std::string("driver table has no ") + function + "() (a null pointer)");
    }
  }
  const std::string name = one_line(table_->name, 64);

  std::array<char, 256> error{};
  device_ = table_->open(config.c_str(), error.data(), error.size());
  if (device_ == nullptr) {
    error.back() = '\0';
    const std::string message = one_line(error.data(), error.size());
    throw Error(where, "open() failed: " + (message.empty() ? "(no message)" : message));
  }
  try {
    hapsim_driver_limits limits;
    std::memset(&limits, 0, sizeof limits);
    table_->rated_limits(device_, &limits);
    profile_ = profile_from_limits(limits, name, path);
  } catch (...) {
    table_->close(device_);  // the destructor does not run for a constructor that throws
    throw;
  }
  stale_reason_ = "no new sample from driver '" + name + "' for more than " +
                  std::to_string(options_.stale_after_s) + " s";
  failed_reason_ = "no new sample from driver '" + name + "' for more than " +
                   std::to_string(options_.failed_after_s) + " s";
  last_good_.healthy = false;
  set_status(DeviceHealth::kStale, "no sample from the driver yet");
}

PluginDevice::~PluginDevice() {
  hapsim_driver_command zero;
  std::memset(&zero, 0, sizeof zero);
  table_->write_command(device_, &zero);
  table_->close(device_);
}

void PluginDevice::set_status(DeviceHealth health, std::string_view reason) noexcept {
  health_ = health;
  reason_length_ = std::min(reason.size(), reason_.size());
  std::copy_n(reason.data(), reason_length_, reason_.data());
}

void PluginDevice::fail_for_good(std::string_view what) noexcept {
  failed_for_good_.store(true, std::memory_order_release);
  constexpr std::string_view kSuffix = "; device not trusted until reopened";
  std::array<char, 192> text{};
  const std::size_t n = std::min(what.size(), text.size() - kSuffix.size());
  std::copy_n(what.data(), n, text.data());
  std::copy_n(kSuffix.data(), kSuffix.size(), text.data() + n);
  set_status(DeviceHealth::kFailed, std::string_view(text.data(), n + kSuffix.size()));
}

DeviceStatus PluginDevice::status() const noexcept {
  return {health_, std::string_view(reason_.data(), reason_length_)};
}

PluginDeviceCounts PluginDevice::counts() const noexcept {
  return {reads_, no_sample_, bad_samples_, commands_zeroed_.load(std::memory_order_relaxed),
          write_refused_.load(std::memory_order_relaxed)};
}

// haptic path
DeviceInput PluginDevice::read(double time_s) noexcept {
  ++reads_;
  if (!fresh_since_s_) {
    fresh_since_s_ = time_s;
  }
  DeviceInput in = last_good_;
  in.time_s = time_s;
  if (failed_for_good_.load(std::memory_order_acquire)) {
    in.healthy = false;
    return in;
  }

  hapsim_driver_state s;
  std::memset(&s, 0, sizeof s);
  if (table_->read_state(device_, time_s, &s) != 0) {
    ++no_sample_;
  } else if (const char* problem = state_problem(s)) {
    ++bad_samples_;
    fail_for_good(problem);
    in.healthy = false;
    return in;
  } else {
    in.p_world = Vec3(s.position_m[0], s.position_m[1], s.position_m[2]);
    in.q_world = Quat(s.orientation_wxyz[0], s.orientation_wxyz[1], s.orientation_wxyz[2],
                      s.orientation_wxyz[3])
                     .normalized();
    in.finger_count = s.finger_count;
    in.finger_rad = {};
    std::copy_n(s.finger_rad, s.finger_count, in.finger_rad.begin());
    in.joint_count = s.joint_count;
    in.joint_rad = {};
    std::copy_n(s.joint_rad, s.joint_count, in.joint_rad.begin());
    in.buttons = s.buttons;
    velocity_m_per_s_ = Vec3(s.velocity_m_per_s[0], s.velocity_m_per_s[1], s.velocity_m_per_s[2]);
    if (!has_sample_ || s.timestamp_s != driver_timestamp_s_) {
      fresh_since_s_ = time_s;
    }
    driver_timestamp_s_ = s.timestamp_s;
    has_sample_ = true;
    last_good_ = in;
  }

  // The worse of what the driver says and what hapsim sees (no sample, a frozen timestamp).
  hapsim_driver_health h;
  std::memset(&h, 0, sizeof h);
  table_->health(device_, &h);
  DeviceHealth driver = DeviceHealth::kFailed;
  std::string_view driver_reason = bounded(h.reason);
  switch (h.code) {
    case HAPSIM_DRIVER_HEALTH_OK:
      driver = DeviceHealth::kConnected;
      break;
    case HAPSIM_DRIVER_HEALTH_STALE:
      driver = DeviceHealth::kStale;
      break;
    case HAPSIM_DRIVER_HEALTH_FAILED:
      break;
    default:
      driver_reason = "health() gave an unknown code";
      break;
  }
  if (driver != DeviceHealth::kConnected && driver_reason.empty()) {
    driver_reason = "the driver gave no reason";
  }
  const double age_s = time_s - *fresh_since_s_;
  DeviceHealth seen = DeviceHealth::kConnected;
  std::string_view seen_reason;
  if (age_s > options_.failed_after_s) {
    seen = DeviceHealth::kFailed;
    seen_reason = failed_reason_;
  } else if (age_s > options_.stale_after_s) {
    seen = DeviceHealth::kStale;
    seen_reason = stale_reason_;
  } else if (!has_sample_) {
    seen = DeviceHealth::kStale;
    seen_reason = "no sample from the driver yet";
  }
  if (static_cast<int>(driver) >= static_cast<int>(seen)) {
    set_status(driver, driver_reason);
  } else {
    set_status(seen, seen_reason);
  }
  in.healthy = health_ == DeviceHealth::kConnected;
  return in;
}

// haptic path
void PluginDevice::write(const DeviceCommand& command) noexcept {
  hapsim_driver_command out;
  std::memset(&out, 0, sizeof out);
  DeviceCommand sent;
  bool finite = command.force_world_n.allFinite();
  const int fingers = std::clamp(command.finger_count, 0, profile_.finger_count);
  const int joints = std::clamp(command.joint_count, 0, kMaxDeviceJoints);
  for (int i = 0; i < fingers; ++i) {
    finite = finite && std::isfinite(command.finger_force_n[static_cast<std::size_t>(i)]);
  }
  for (int i = 0; i < joints; ++i) {
    finite = finite && std::isfinite(command.joint_torque_nm[static_cast<std::size_t>(i)]);
  }
  // A NaN anywhere means the producer is broken: send nothing of it (zero), rather than the
  // channels that look fine.
  if (!finite || failed_for_good_.load(std::memory_order_acquire)) {
    commands_zeroed_.fetch_add(1, std::memory_order_relaxed);
  } else {
    Vec3 force = command.force_world_n;
    const double norm = force.norm();
    if (norm > profile_.max_force_n) {
      force *= profile_.max_force_n / norm;  // direction kept, size capped (never amplified)
    }
    sent.force_world_n = force;
    sent.finger_count = fingers;
    for (int i = 0; i < fingers; ++i) {
      const auto k = static_cast<std::size_t>(i);
      sent.finger_force_n[k] =
          std::clamp(command.finger_force_n[k], 0.0, profile_.max_finger_force_n);
    }
    sent.joint_count = joints;
    for (int i = 0; i < joints; ++i) {
      const auto k = static_cast<std::size_t>(i);
      sent.joint_torque_nm[k] = std::clamp(
          command.joint_torque_nm[k], -profile_.max_joint_torque_nm, profile_.max_joint_torque_nm);
    }
    for (int axis = 0; axis < 3; ++axis) {
      out.force_n[axis] = sent.force_world_n[axis];
    }
    out.finger_count = sent.finger_count;
    std::copy_n(sent.finger_force_n.begin(), fingers, out.finger_force_n);
    out.joint_count = sent.joint_count;
    std::copy_n(sent.joint_torque_nm.begin(), joints, out.joint_torque_nm);
  }
  if (table_->write_command(device_, &out) != 0) {
    write_refused_.fetch_add(1, std::memory_order_relaxed);
  }
  last_sent_ = sent;
}

std::unique_ptr<PluginDevice> open_plugin_device(const std::filesystem::path& path,
                                                 const std::string& config,
                                                 PluginDeviceOptions options) {
  return std::make_unique<PluginDevice>(path, config, options);
}

std::optional<std::filesystem::path> plugin_path_from_device_spec(std::string_view device_spec) {
  constexpr std::string_view kPrefix = "plugin:";
  if (!device_spec.starts_with(kPrefix)) {
    return std::nullopt;
  }
  device_spec.remove_prefix(kPrefix.size());
  if (device_spec.empty()) {
    throw Error("--device", "'plugin:' needs the driver's path, e.g. plugin:./libmy_device.so");
  }
  return std::filesystem::path(device_spec);
}

}  // namespace hapsim
