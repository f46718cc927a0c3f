// What `hapsim doctor` checks about the machine (docs/doctor.md): each check measures one thing
// the haptic loop, the network or the pictures depend on, and says it as a status, one line of
// explanation and one line of fix a user would apply. The checks that need no display or network
// library live here (headless, layer 5); the command adds the EGL probe (render/), the 3D mouse
// and the secure key folder (net/) on top.
//
// Every probe leaves the process as it found it: SCHED_FIFO is tried on a throwaway thread, and
// mlockall in a forked child that exits at once.
#pragma once

#include <nlohmann/json.hpp>

#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

namespace hapsim {

enum class CheckStatus : std::uint8_t {
  kOk,    ///< works as hapsim wants it
  kWarn,  ///< hapsim runs, but worse (jitter, no window, no 3D mouse) or only on this machine
  kFail,  ///< what was asked for cannot work (a plugin that does not open, a bad key folder)
};

/// "ok", "warn" or "fail".
[[nodiscard]] std::string_view check_status_name(CheckStatus status);

struct SystemCheck {
  std::string name;  ///< short and stable: "realtime", "memlock", "cpu-governor", …
  CheckStatus status = CheckStatus::kOk;
  std::string explanation;  ///< one line: what was found and what it means for hapsim
  std::string fix;          ///< one line: what a user applies; empty when there is nothing to do
  nlohmann::json details = nlohmann::json::object();  ///< the measured values, for --json
};

/// A resource limit as getrlimit reports it; nullopt is RLIM_INFINITY.
struct ResourceLimit {
  std::optional<std::uint64_t> soft;
  std::optional<std::uint64_t> hard;
};

/// What the real-time check measured (kept apart from the probing so the judgement is testable).
struct RealtimeFacts {
  ResourceLimit rtprio;
  /// The priority the haptic loop asks for (HapticLoopOptions::fifo_priority).
  int priority = 80;
  /// SCHED_FIFO at `priority` was actually set on a thread.
  bool fifo_permitted = false;
  /// CAP_SYS_NICE in the effective set (root has it): the limit does not apply.
  bool privileged = false;
};

/// Judges RealtimeFacts: ok when SCHED_FIFO was set; warn (the loop falls back to normal
/// scheduling) when not, with the /etc/security/limits.conf line or LimitRTPRIO= as the fix.
[[nodiscard]] SystemCheck judge_realtime(const RealtimeFacts& facts);
/// RLIMIT_RTPRIO and SCHED_FIFO at `priority`, tried on a throwaway thread.
[[nodiscard]] RealtimeFacts probe_realtime(int priority);
[[nodiscard]] SystemCheck check_realtime_priority(int priority);

struct MemoryLockFacts {
  ResourceLimit memlock;  ///< bytes
  bool root = false;
  /// The build has a sanitizer with shadow memory: the loop never locks.
  bool sanitizer = false;
  /// mlockall(MCL_CURRENT | MCL_FUTURE | MCL_ONFAULT) succeeded in a forked child.
  bool mlockall_works = false;
  int mlockall_errno = 0;
};

/// Judges MemoryLockFacts by the haptic loop's own rule (try_lock_process_memory: it locks only
/// as root or with an unlimited RLIMIT_MEMLOCK, never under a sanitizer).
[[nodiscard]] SystemCheck judge_memory_lock(const MemoryLockFacts& facts);
[[nodiscard]] MemoryLockFacts probe_memory_lock();
[[nodiscard]] SystemCheck check_memory_lock();

/// The CPU frequency governors under `cpu_root` (cpuN/cpufreq/scaling_governor): all
/// "performance" is ok, another is a warning, none at all (a VM) is ok and "unknown".
[[nodiscard]] SystemCheck check_cpu_governor(
    const std::filesystem::path& cpu_root = "/sys/devices/system/cpu");

/// DISPLAY / WAYLAND_DISPLAY (and the X server's socket for a local DISPLAY): a window for
/// `hapsim view`. Pictures without a display are the EGL check's (the command's).
[[nodiscard]] SystemCheck check_display();

/// One network interface as getifaddrs reports it.
struct NetworkInterface {
  std::string name;
  bool up = false;
  bool loopback = false;
  bool multicast = false;
  std::vector<std::string> addresses;
};

[[nodiscard]] std::vector<NetworkInterface> network_interfaces();

/// CYCLONEDDS_URI (set or not; the files it names exist) and the interfaces Cyclone DDS could
/// use: up, not loopback, multicast-capable. `default_config`: the loopback-only config hapsim's
/// network commands use when CYCLONEDDS_URI is not set.
[[nodiscard]] SystemCheck judge_dds(const char* cyclonedds_uri,
                                    const std::filesystem::path& default_config,
                                    const std::vector<NetworkInterface>& interfaces);
[[nodiscard]] SystemCheck check_dds(const std::filesystem::path& default_config);

/// The real-data folder as scenes find it (core/data_dir.h): `given` (--data) when not empty,
/// else $HAPSIM_DATA, else `beside_checkout` (../shared/data beside the checkout holding the
/// scenes). Missing is a warning (only scenes that use real data need it); a given folder that
/// does not exist fails.
[[nodiscard]] SystemCheck check_data_folder(const std::filesystem::path& given,
                                            const std::filesystem::path& beside_checkout);

/// Opens the driver plugin at `path` with `config` (device/plugin_device.h), reads once, closes
/// it: its name and rated limits, or the loader's one-line error (a failure).
[[nodiscard]] SystemCheck check_plugin_device(const std::filesystem::path& path,
                                              const std::string& config);

/// Whether any check failed (`hapsim doctor` then exits 1).
[[nodiscard]] bool any_failed(const std::vector<SystemCheck>& checks);

/// {"ok": no failure, "failed": n, "warnings": n, "checks": [{name, status, explanation, fix,
/// details}]}.
[[nodiscard]] nlohmann::json checks_json(const std::vector<SystemCheck>& checks);

/// The human table: one row per check (name, status, explanation), the fix on the line below a
/// warning or a failure (and below an ok that has one), then a one-line verdict.
[[nodiscard]] std::string format_checks_table(const std::vector<SystemCheck>& checks);

}  // namespace hapsim
