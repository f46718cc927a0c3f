#include "hapsim/runtime/system_check.h"

#include "hapsim/core/data_dir.h"
#include "hapsim/core/error.h"
#include "hapsim/core/sanitizer_build.h"
#include "hapsim/device/plugin_device.h"
#include "hapsim/runtime/deadline_clock.h"

#include <ifaddrs.h>
#include <net/if.h>
#include <netdb.h>
#include <sys/mman.h>
#include <sys/resource.h>
#include <sys/socket.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cctype>
#include <cerrno>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <iterator>
#include <map>
#include <memory>
#include <sstream>
#include <system_error>
#include <thread>

namespace hapsim {
// Named, not anonymous: hapsim_headless is a unity build, and helpers such as trim() exist in
// other files too.
namespace syscheck {

ResourceLimit read_limit(int resource) {
  rlimit l{};
  ResourceLimit r;
  if (getrlimit(resource, &l) != 0) {
    r.soft = 0;
    r.hard = 0;
    return r;
  }
  if (l.rlim_cur != RLIM_INFINITY) {
    r.soft = static_cast<std::uint64_t>(l.rlim_cur);
  }
  if (l.rlim_max != RLIM_INFINITY) {
    r.hard = static_cast<std::uint64_t>(l.rlim_max);
  }
  return r;
}

nlohmann::json limit_json(const std::optional<std::uint64_t>& v) {
  return v ? nlohmann::json(*v) : nlohmann::json("unlimited");
}

std::string limit_text(const std::optional<std::uint64_t>& v) {
  return v ? std::to_string(*v) : std::string("unlimited");
}

std::string bytes_text(const std::optional<std::uint64_t>& v) {
  if (!v) {
    return "unlimited";
  }
  char text[64];
  if (*v >= (std::uint64_t{1} << 30)) {
    std::snprintf(text, sizeof text, "%.1f GiB", static_cast<double>(*v) / (1 << 30));
  } else if (*v >= (std::uint64_t{1} << 20)) {
    std::snprintf(text, sizeof text, "%.0f MiB", static_cast<double>(*v) / (1 << 20));
  } else {
    std::snprintf(text, sizeof text, "%.0f KiB", static_cast<double>(*v) / 1024.0);
  }
  return text;
}

// CAP_SYS_NICE (bit 23) in /proc/self/status's CapEff.
bool has_cap_sys_nice() {
  std::ifstream in("/proc/self/status");
  for (std::string line; std::getline(in, line);) {
    if (line.rfind("CapEff:", 0) == 0) {
      const std::uint64_t caps = std::strtoull(line.c_str() + 7, nullptr, 16);
      return (caps >> 23U) & 1U;
    }
  }
  return geteuid() == 0;
}

std::string trim(std::string s) {
  const auto not_space = [](unsigned char c) { return std::isspace(c) == 0; };
  s.erase(s.begin(), std::find_if(s.begin(), s.end(), not_space));
  s.erase(std::find_if(s.rbegin(), s.rend(), not_space).base(), s.end());
  return s;
}

bool starts_with(const std::string& s, std::string_view prefix) {
  return s.rfind(prefix, 0) == 0;
}

}  // namespace syscheck

std::string_view check_status_name(CheckStatus status) {
  switch (status) {
    case CheckStatus::kOk:
      return "ok";
    case CheckStatus::kWarn:
      return "warn";
    case CheckStatus::kFail:
      return "fail";
  }
  return "?";
}

// ---- real-time priority ----------------------------------------------------------------------

RealtimeFacts probe_realtime(int priority) {
  RealtimeFacts f;
  f.rtprio = syscheck::read_limit(RLIMIT_RTPRIO);
  f.priority = priority;
  f.privileged = syscheck::has_cap_sys_nice();
  // The haptic loop's own call, on a thread that ends at once: nothing of this process keeps
  // the policy.
  bool permitted = false;
  std::thread probe([&permitted, priority] { permitted = try_set_realtime_priority(priority); });
  probe.join();
  f.fifo_permitted = permitted;
  return f;
}

SystemCheck judge_realtime(const RealtimeFacts& f) {
  SystemCheck c;
  c.name = "realtime";
  const std::string p = std::to_string(f.priority);
  const std::string limits = "RLIMIT_RTPRIO soft " + syscheck::limit_text(f.rtprio.soft) +
                             ", hard " + syscheck::limit_text(f.rtprio.hard);
  const bool limit_allows =
      !f.rtprio.soft || *f.rtprio.soft >= static_cast<std::uint64_t>(f.priority);
  const std::string limits_conf = "add '@realtime - rtprio " + p +
                                  "' to /etc/security/limits.conf, put the user in group "
                                  "realtime and log in again (a systemd service: LimitRTPRIO=" +
                                  p + ")";
  c.details = {{"rtprio_soft", syscheck::limit_json(f.rtprio.soft)},
               {"rtprio_hard", syscheck::limit_json(f.rtprio.hard)},
               {"priority", f.priority},
               {"sched_fifo", f.fifo_permitted},
               {"privileged", f.privileged}};
  if (f.fifo_permitted) {
    c.status = CheckStatus::kOk;
    if (!limit_allows && f.privileged) {
      c.explanation = "SCHED_FIFO at priority " + p + " permitted by privilege (root or " +
                      "CAP_SYS_NICE), not by the limit (" + limits +
                      "): the haptic loop runs real time";
      c.fix = "nothing as this user; for another user: " + limits_conf;
    } else {
      c.explanation = "SCHED_FIFO at priority " + p + " permitted (" + limits +
                      "): the haptic loop runs real time";
    }
    return c;
  }
  c.status = CheckStatus::kWarn;
  const std::string falls_back =
      ": `hapsim run --realtime`, serve, device and the viewer fall back to normal scheduling "
      "(millisecond jitter)";
  if (!limit_allows) {
    c.explanation = "SCHED_FIFO at priority " + p + " refused: RLIMIT_RTPRIO soft " +
                    syscheck::limit_text(f.rtprio.soft) + " (hard " +
                    syscheck::limit_text(f.rtprio.hard) + ") is below " + p + falls_back;
    const bool hard_allows =
        !f.rtprio.hard || *f.rtprio.hard >= static_cast<std::uint64_t>(f.priority);
    c.fix = hard_allows ? "raise the soft limit in the shell that starts hapsim: ulimit -r " + p +
                              " (the hard limit allows it); for good: " + limits_conf
                        : limits_conf;
  } else {
    c.explanation = "SCHED_FIFO at priority " + p + " refused although " + limits +
                    " allows it (a container without CAP_SYS_NICE, or no real-time budget in "
                    "this cgroup)" +
                    falls_back;
    c.fix =
        "give the container CAP_SYS_NICE and an rtprio limit (docker run --cap-add=SYS_NICE "
        "--ulimit rtprio=" +
        p + "), or check /proc/sys/kernel/sched_rt_runtime_us and the cgroup's cpu.rt_runtime_us";
  }
  return c;
}

SystemCheck check_realtime_priority(int priority) {
  return judge_realtime(probe_realtime(priority));
}

// ---- memory locking --------------------------------------------------------------------------

MemoryLockFacts probe_memory_lock() {
  MemoryLockFacts f;
  f.memlock = syscheck::read_limit(RLIMIT_MEMLOCK);
  f.root = geteuid() == 0;
  f.sanitizer = kBuiltWithShadowSanitizer;
  if (f.sanitizer) {
    return f;  // terabytes of shadow: never tried, as the loop never tries
  }
  // In a child that exits at once: this process never has its memory locked.
  const pid_t pid = ::fork();
  if (pid == 0) {
    const int r = ::mlockall(MCL_CURRENT | MCL_FUTURE | MCL_ONFAULT);
    ::_exit(r == 0 ? 0 : (errno > 0 && errno < 255 ? errno : 254));
  }
  if (pid < 0) {
    f.mlockall_errno = errno;
    return f;
  }
  int status = 0;
  while (::waitpid(pid, &status, 0) < 0 && errno == EINTR) {
  }
  if (WIFEXITED(status)) {
    f.mlockall_works = WEXITSTATUS(status) == 0;
    f.mlockall_errno = WEXITSTATUS(status);
  } else {
    f.mlockall_errno = EINTR;
  }
  return f;
}

SystemCheck judge_memory_lock(const MemoryLockFacts& f) {
  SystemCheck c;
  c.name = "memlock";
  const std::string limits = "RLIMIT_MEMLOCK soft " + syscheck::bytes_text(f.memlock.soft) +
                             ", hard " + syscheck::bytes_text(f.memlock.hard);
  c.details = {{"memlock_soft_bytes", syscheck::limit_json(f.memlock.soft)},
               {"memlock_hard_bytes", syscheck::limit_json(f.memlock.hard)},
               {"root", f.root},
               {"sanitizer_build", f.sanitizer},
               {"mlockall", f.mlockall_works}};
  const std::string fix =
      "add '@realtime - memlock unlimited' to /etc/security/limits.conf and log in again (a "
      "systemd service: LimitMEMLOCK=infinity)";
  const bool loop_would_lock = !f.sanitizer && (f.root || !f.memlock.soft);
  c.details["haptic_loop_locks"] = loop_would_lock && f.mlockall_works;
  if (f.sanitizer) {
    c.status = CheckStatus::kWarn;
    c.explanation = "a sanitizer build: the haptic loop never locks memory (" + limits + ")";
    c.fix = "measure real time with the release build";
    return c;
  }
  if (!loop_would_lock) {
    c.status = CheckStatus::kWarn;
    c.explanation = limits +
                    " and not root: the haptic loop does not lock its memory (a locked budget "
                    "that small would make a later allocation fail), so a page read back from "
                    "swap can stall a cycle";
    c.fix = fix;
    return c;
  }
  if (!f.mlockall_works) {
    c.status = CheckStatus::kWarn;
    c.explanation = "mlockall refused (" + std::string(std::strerror(f.mlockall_errno)) +
                    ") with " + limits + ": the haptic loop runs with its memory unlocked";
    c.fix = fix + "; in a container also --cap-add=IPC_LOCK";
    return c;
  }
  c.status = CheckStatus::kOk;
  c.explanation = "mlockall works (" + limits + (f.root ? ", root" : "") +
                  "): the haptic loop locks its memory";
  return c;
}

SystemCheck check_memory_lock() {
  return judge_memory_lock(probe_memory_lock());
}

// ---- CPU frequency governor ------------------------------------------------------------------

SystemCheck check_cpu_governor(const std::filesystem::path& cpu_root) {
  SystemCheck c;
  c.name = "cpu-governor";
  std::map<std::string, std::vector<int>> cpus_by_governor;
  std::error_code ec;
  for (const auto& entry : std::filesystem::directory_iterator(cpu_root, ec)) {
    const std::string name = entry.path().filename().string();
    if (name.size() < 4 || !syscheck::starts_with(name, "cpu") ||
        !std::all_of(name.begin() + 3, name.end(),
                     [](unsigned char ch) { return std::isdigit(ch) != 0; })) {
      continue;
    }
    std::ifstream in(entry.path() / "cpufreq" / "scaling_governor");
    std::string governor;
    if (in && std::getline(in, governor) && !syscheck::trim(governor).empty()) {
      cpus_by_governor[syscheck::trim(governor)].push_back(std::stoi(name.substr(3)));
    }
  }
  nlohmann::json governors = nlohmann::json::object();
  for (auto& [governor, cpus] : cpus_by_governor) {
    std::sort(cpus.begin(), cpus.end());
    governors[governor] = cpus;
  }
  c.details = {{"governors", governors}};
  if (cpus_by_governor.empty()) {
    c.status = CheckStatus::kOk;
    c.details["governor"] = "unknown";
    c.explanation = "unknown: no " + (cpu_root / "cpu*/cpufreq/scaling_governor").string() +
                    " here (a virtual machine or a fixed clock: nothing to set)";
    return c;
  }
  std::string found;
  for (const auto& [governor, cpus] : cpus_by_governor) {
    found += (found.empty() ? "" : ", ") + governor + " on " + std::to_string(cpus.size()) +
             " CPU" + (cpus.size() == 1 ? "" : "s");
  }
  if (cpus_by_governor.size() == 1 && cpus_by_governor.begin()->first == "performance") {
    c.status = CheckStatus::kOk;
    c.details["governor"] = "performance";
    c.explanation = found + ": the clock stays up between haptic cycles";
    return c;
  }
  c.status = CheckStatus::kWarn;
  c.details["governor"] = cpus_by_governor.size() == 1 ? cpus_by_governor.begin()->first : "mixed";
  c.explanation = found +
                  ": the clock may drop between 1 ms cycles and each cycle then starts slow "
                  "(jitter)";
  c.fix =
      "sudo cpupower frequency-set -g performance (Debian: linux-cpupower), or echo performance "
      "| sudo tee " +
      (cpu_root / "cpu*/cpufreq/scaling_governor").string();
  return c;
}

// ---- display ---------------------------------------------------------------------------------

SystemCheck check_display() {
  SystemCheck c;
  c.name = "display";
  const char* display = std::getenv("DISPLAY");
  const char* wayland = std::getenv("WAYLAND_DISPLAY");
  const bool has_x = display != nullptr && *display != '\0';
  const bool has_wayland = wayland != nullptr && *wayland != '\0';
  c.details = {
      {"DISPLAY", has_x ? nlohmann::json(display) : nlohmann::json(nullptr)},
      {"WAYLAND_DISPLAY", has_wayland ? nlohmann::json(wayland) : nlohmann::json(nullptr)}};
  const std::string headless =
      "run the viewer in a desktop session or under xvfb-run -a -s '-screen 0 1280x720x24' "
      "hapsim view SCENE; without a window: hapsim run SCENE --snapshot FILE.png";
  if (!has_x && !has_wayland) {
    c.status = CheckStatus::kWarn;
    c.explanation =
        "no DISPLAY or WAYLAND_DISPLAY: `hapsim view` cannot open a window (offscreen pictures "
        "need none: see the pictures check)";
    c.fix = headless;
    return c;
  }
  if (has_x && display[0] == ':') {
    // A local X server listens on /tmp/.X11-unix/X<N> (":N" or ":N.S").
    const std::string number = std::string(display + 1).substr(0, std::strcspn(display + 1, "."));
    const std::filesystem::path socket = "/tmp/.X11-unix/X" + number;
    std::error_code ec;
    const bool listening = std::filesystem::exists(socket, ec);
    c.details["x_socket"] = socket.string();
    c.details["x_socket_exists"] = listening;
    if (!listening && !has_wayland) {
      c.status = CheckStatus::kWarn;
      c.explanation = std::string("DISPLAY=") + display + " but no X server listens on " +
                      socket.string() + ": `hapsim view` will not open a window";
      c.fix = "start the X server (or unset DISPLAY); or " + headless;
      return c;
    }
  }
  c.status = CheckStatus::kOk;
  c.explanation = std::string("a display for `hapsim view`: ") +
                  (has_x ? std::string("DISPLAY=") + display : std::string()) +
                  (has_x && has_wayland ? ", " : "") +
                  (has_wayland ? std::string("WAYLAND_DISPLAY=") + wayland : std::string());
  return c;
}

// ---- Cyclone DDS -----------------------------------------------------------------------------

std::vector<NetworkInterface> network_interfaces() {
  std::vector<NetworkInterface> out;
  ifaddrs* list = nullptr;
  if (::getifaddrs(&list) != 0) {
    return out;
  }
  for (const ifaddrs* a = list; a != nullptr; a = a->ifa_next) {
    if (a->ifa_name == nullptr) {
      continue;
    }
    auto it = std::find_if(out.begin(), out.end(),
                           [a](const NetworkInterface& n) { return n.name == a->ifa_name; });
    if (it == out.end()) {
      out.push_back({a->ifa_name, false, false, false, {}});
      it = std::prev(out.end());
    }
    it->up = it->up || (a->ifa_flags & IFF_UP) != 0;
    it->loopback = it->loopback || (a->ifa_flags & IFF_LOOPBACK) != 0;
    it->multicast = it->multicast || (a->ifa_flags & IFF_MULTICAST) != 0;
    if (a->ifa_addr != nullptr &&
        (a->ifa_addr->sa_family == AF_INET || a->ifa_addr->sa_family == AF_INET6)) {
      char host[NI_MAXHOST] = {};
      const socklen_t length =
          a->ifa_addr->sa_family == AF_INET ? sizeof(sockaddr_in) : sizeof(sockaddr_in6);
      if (::getnameinfo(a->ifa_addr, length, host, sizeof host, nullptr, 0, NI_NUMERICHOST) == 0) {
        it->addresses.emplace_back(host);
      }
    }
  }
  ::freeifaddrs(list);
  return out;
}

SystemCheck judge_dds(const char* cyclonedds_uri, const std::filesystem::path& default_config,
                      const std::vector<NetworkInterface>& interfaces) {
  SystemCheck c;
  c.name = "dds";
  const bool user_config = cyclonedds_uri != nullptr && *cyclonedds_uri != '\0';
  nlohmann::json ifs = nlohmann::json::array();
  std::vector<const NetworkInterface*> usable;
  for (const NetworkInterface& n : interfaces) {
    ifs.push_back({{"name", n.name},
                   {"up", n.up},
                   {"loopback", n.loopback},
                   {"multicast", n.multicast},
                   {"addresses", n.addresses}});
    if (n.up && !n.loopback && !n.addresses.empty()) {
      usable.push_back(&n);
    }
  }
  c.details = {
      {"CYCLONEDDS_URI", user_config ? nlohmann::json(cyclonedds_uri) : nlohmann::json(nullptr)},
      {"default_config", default_config.string()},
      {"interfaces", ifs}};
  // The configuration: the user's files must exist, else every network command fails to start.
  std::string config;
  if (user_config) {
    std::vector<std::string> missing;
    std::stringstream items(cyclonedds_uri);
    for (std::string item; std::getline(items, item, ',');) {
      item = syscheck::trim(item);
      if (item.empty() || item[0] == '<') {
        continue;  // raw XML
      }
      std::string file = syscheck::starts_with(item, "file://") ? item.substr(7) : item;
      std::error_code ec;
      if (!std::filesystem::is_regular_file(file, ec)) {
        missing.push_back(file);
      }
    }
    if (!missing.empty()) {
      c.status = CheckStatus::kFail;
      c.explanation = "CYCLONEDDS_URI names " + missing.front() +
                      ", which is not a file: serve, device, watch and view --connect cannot "
                      "start";
      c.fix =
          "point CYCLONEDDS_URI at an existing config (file:///path/to/cyclonedds.xml), or "
          "unset it to use hapsim's loopback config " +
          default_config.string();
      return c;
    }
    config = std::string("CYCLONEDDS_URI=") + cyclonedds_uri + " (yours: its interfaces apply)";
  } else {
    std::error_code ec;
    if (!std::filesystem::is_regular_file(default_config, ec)) {
      c.status = CheckStatus::kFail;
      c.explanation = "CYCLONEDDS_URI not set and hapsim's own config " + default_config.string() +
                      " is missing: the network commands cannot start";
      c.fix = "reinstall hapsim, or set CYCLONEDDS_URI=file:///path/to/cyclonedds.xml";
      return c;
    }
    config = "CYCLONEDDS_URI not set: hapsim uses its loopback-only config unless --interface NAME";
  }
  if (usable.empty()) {
    c.status = CheckStatus::kWarn;
    c.explanation = config +
                    "; only loopback is up: serve, device hosts and viewers reach each other on "
                    "this machine only";
    c.fix =
        "to run hosts on two machines, bring a network interface up, then give both --interface "
        "NAME (and --peer HOST where there is no multicast)";
    return c;
  }
  std::string names;
  bool any_multicast = false;
  for (const NetworkInterface* n : usable) {
    names += (names.empty() ? "" : ", ") + n->name + " (" + n->addresses.front() +
             (n->multicast ? ", multicast" : ", no multicast") + ")";
    any_multicast = any_multicast || n->multicast;
  }
  if (!any_multicast) {
    c.status = CheckStatus::kWarn;
    c.explanation = config + "; interfaces: " + names +
                    ": none can multicast, so hosts do not discover each other by themselves";
    c.fix = "give --interface NAME --peer HOST (each other machine) on every host";
    return c;
  }
  c.status = CheckStatus::kOk;
  c.explanation = config + "; interfaces for --interface: " + names;
  return c;
}

SystemCheck check_dds(const std::filesystem::path& default_config) {
  return judge_dds(std::getenv("CYCLONEDDS_URI"), default_config, network_interfaces());
}

// ---- real data -------------------------------------------------------------------------------

SystemCheck check_data_folder(const std::filesystem::path& given,
                              const std::filesystem::path& beside_checkout) {
  SystemCheck c;
  c.name = "data";
  std::error_code ec;
  const auto contents = [](const std::filesystem::path& dir) {
    std::vector<std::string> names;
    std::error_code e;
    for (const auto& entry : std::filesystem::directory_iterator(dir, e)) {
      if (entry.is_directory(e)) {
        names.push_back(entry.path().filename().string());
      }
    }
    std::sort(names.begin(), names.end());
    return names;
  };
  const auto found = [&](const std::filesystem::path& dir, const std::string& how) {
    const std::vector<std::string> names = contents(dir);
    std::string list;
    for (const std::string& n : names) {
      list += (list.empty() ? "" : ", ") + n;
    }
    c.details["path"] = dir.string();
    c.details["from"] = how;
    c.details["folders"] = names;
    c.status = CheckStatus::kOk;
    c.explanation = "found " + dir.string() + " (" + how + ")" +
                    (list.empty() ? std::string(": empty") : ": " + list);
  };
  const char* env = std::getenv("HAPSIM_DATA");
  const bool env_set = env != nullptr && *env != '\0';
  c.details = {{"HAPSIM_DATA", env_set ? nlohmann::json(env) : nlohmann::json(nullptr)},
               {"beside_checkout", beside_checkout.lexically_normal().string()}};
  if (!given.empty()) {
    if (std::filesystem::is_directory(given, ec)) {
      found(given, "--data");
    } else {
      c.status = CheckStatus::kFail;
      c.details["path"] = given.string();
      c.explanation = "--data " + given.string() + ": no such folder";
      c.fix = "give the folder holding the real data (e.g. knee_vhf_left/)";
    }
    return c;
  }
  const std::optional<std::filesystem::path> root = find_data_dir(beside_checkout);
  if (root && env_set && std::filesystem::path(env) == *root) {
    found(*root, "HAPSIM_DATA");
    return c;
  }
  if (root) {
    found(root->lexically_normal(), "beside the checkout");
    if (env_set) {
      c.status = CheckStatus::kWarn;
      c.explanation = std::string("HAPSIM_DATA=") + env + " does not exist; scenes use " +
                      root->lexically_normal().string() + " beside the checkout instead";
      c.fix = "set HAPSIM_DATA to an existing folder, or unset it";
    }
    return c;
  }
  c.status = CheckStatus::kWarn;
  c.details["path"] = nullptr;
  c.explanation = std::string("no real-data folder (") +
                  (env_set ? std::string("HAPSIM_DATA=") + env + " does not exist; " : "") +
                  "looked in " + beside_checkout.lexically_normal().string() +
                  "): scenes that use real data (the default knee) do not load; the others run";
  c.fix = "set HAPSIM_DATA=/path/to/data, or give --data DIR to run and view";
  return c;
}

// ---- a driver plugin -------------------------------------------------------------------------

SystemCheck check_plugin_device(const std::filesystem::path& path, const std::string& config) {
  SystemCheck c;
  c.name = "plugin";
  c.details = {{"path", path.string()}, {"config", config}};
  try {
    const std::unique_ptr<PluginDevice> device = open_plugin_device(path, config);
    (void)device->read(0.0);
    const DeviceStatus status = device->status();
    const DeviceProfile& p = device->profile();
    c.details["driver"] = device->driver_name();
    c.details["model"] = p.display_name;
    c.details["max_force_n"] = p.max_force_n;
    c.details["max_stiffness_n_per_m"] = p.max_stiffness_n_per_m;
    c.details["fingers"] = p.finger_count;
    c.details["health"] = std::string(to_string(status.health));
    char limits[160];
    std::snprintf(limits, sizeof limits, "%.1f N, %.0f N/m, %d finger(s)", p.max_force_n,
                  p.max_stiffness_n_per_m, p.finger_count);
    c.status = CheckStatus::kOk;
    c.explanation =
        "opened driver '" + device->driver_name() + "'" +
        (p.display_name.empty() ? std::string() : " (" + p.display_name + ")") + " from " +
        path.string() + ": rated " + limits +
        "; first read: " + std::string(to_string(status.health)) +
        (status.reason.empty() ? std::string() : " (" + std::string(status.reason) + ")");
  } catch (const std::exception& e) {
    c.status = CheckStatus::kFail;
    c.details["error"] = e.what();
    c.explanation = std::string("cannot open the plugin: ") + e.what();
    c.fix =
        "give the path of a driver built against include/hapsim/device_driver.h that exports "
        "hapsim_device_driver_v1 (docs/devices.md); --driver-config STRING is what its open() "
        "gets";
  }
  return c;
}

// ---- the report ------------------------------------------------------------------------------

bool any_failed(const std::vector<SystemCheck>& checks) {
  return std::any_of(checks.begin(), checks.end(),
                     [](const SystemCheck& c) { return c.status == CheckStatus::kFail; });
}

nlohmann::json checks_json(const std::vector<SystemCheck>& checks) {
  nlohmann::json list = nlohmann::json::array();
  std::size_t failed = 0;
  std::size_t warnings = 0;
  for (const SystemCheck& c : checks) {
    failed += c.status == CheckStatus::kFail ? 1 : 0;
    warnings += c.status == CheckStatus::kWarn ? 1 : 0;
    list.push_back({{"name", c.name},
                    {"status", std::string(check_status_name(c.status))},
                    {"explanation", c.explanation},
                    {"fix", c.fix},
                    {"details", c.details}});
  }
  return {{"ok", failed == 0}, {"failed", failed}, {"warnings", warnings}, {"checks", list}};
}

std::string format_checks_table(const std::vector<SystemCheck>& checks) {
  std::size_t width = 5;
  for (const SystemCheck& c : checks) {
    width = std::max(width, c.name.size());
  }
  const auto pad = [](std::string s, std::size_t n) {
    s.resize(std::max(s.size(), n), ' ');
    return s;
  };
  std::string text = pad("check", width) + "  " + pad("status", 6) + "  what\n";
  std::size_t failed = 0;
  std::size_t warnings = 0;
  for (const SystemCheck& c : checks) {
    failed += c.status == CheckStatus::kFail ? 1 : 0;
    warnings += c.status == CheckStatus::kWarn ? 1 : 0;
    text += pad(c.name, width) + "  " + pad(std::string(check_status_name(c.status)), 6) + "  " +
            c.explanation + "\n";
    if (!c.fix.empty()) {
      text += pad("", width) + "  " + pad("", 6) + "  fix: " + c.fix + "\n";
    }
  }
  text += "doctor: " + std::to_string(checks.size()) + " checks, " + std::to_string(failed) +
          " failed, " + std::to_string(warnings) + " warning(s)" +
          (failed > 0 ? " (exit status 1)" : "") + "\n";
  return text;
}

}  // namespace hapsim
