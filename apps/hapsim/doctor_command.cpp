// `hapsim doctor`: checks what the machine gives hapsim and says, per check, ok / warn / fail, one
// line of explanation and the fix a user would apply (docs/doctor.md). The headless checks are
// runtime/system_check.h's (real-time priority, memory locking, CPU governor, display, Cyclone
// DDS's config and interfaces, the real-data folder, a driver plugin); this file adds the ones
// above the headless layers: EGL offscreen pictures (render/offscreen_context.h, the renderer's
// own context), the 3D mouse (libspnav) and a secure session's key folder (net/).
//
// Exit status: 0 when no check failed (warnings included), 1 when one did, 2 for bad options.
#include "commands.h"
#include "json_output.h"
#include "shipped_files.h"

#include "hapsim/core/device_profile.h"
#include "hapsim/core/error.h"
#include "hapsim/device/plugin_device.h"
#include "hapsim/net/security_config.h"
#include "hapsim/net/security_key_dir.h"
#include "hapsim/render/offscreen_context.h"
#include "hapsim/runtime/haptic_loop.h"
#include "hapsim/runtime/system_check.h"
#if defined(HAPSIM_WITH_SPNAV)
#include "hapsim/device/spacenav_device.h"
#endif

#include <nlohmann/json.hpp>

#include <unistd.h>

#include <cstdio>
#include <exception>
#include <filesystem>
#include <iostream>
#include <memory>
#include <string>
#include <system_error>
#include <vector>

namespace hapsim::app {
namespace {

struct DoctorArgs {
  std::string json_path;  // "" or "-": stdout
  std::string device;
  std::string driver_config;
  std::string secure_dir;
  std::string identity;
  std::string data_dir;
};

// Offscreen pictures through the renderer's own EGL surfaceless context (what `hapsim run
// --snapshot` and the main job's picture use): made once, tiny, and dropped.
SystemCheck check_offscreen_pictures(bool has_display) {
  SystemCheck c;
  c.name = "pictures";
  try {
    const OffscreenContext context(64, 64, 1);
    c.details = {{"egl", true}, {"renderer", context.renderer_name()}};
    c.status = CheckStatus::kOk;
    c.explanation = "EGL offscreen OpenGL works (" + context.renderer_name() +
                    "): `hapsim run --snapshot` draws without a display";
  } catch (const std::exception& e) {
    c.details = {{"egl", false}, {"error", e.what()}};
    // With a display the viewer still draws; with neither there are no pictures at all.
    c.status = has_display ? CheckStatus::kWarn : CheckStatus::kFail;
    c.explanation =
        std::string("no EGL offscreen context (") + e.what() +
        "): `hapsim run --snapshot` cannot draw" +
        (has_display ? " (the viewer's window may still)" : ", and there is no display");
    c.fix =
        "apt-get install libegl1 libgl1-mesa-dri (Mesa's llvmpipe draws without a GPU); in a "
        "container, do not hide /usr/share/glvnd/egl_vendor.d";
  }
  return c;
}

// A 3D mouse answering through spacenavd (the device --device spacemouse opens).
SystemCheck check_space_mouse() {
  SystemCheck c;
  c.name = "3d-mouse";
#if defined(HAPSIM_WITH_SPNAV)
  c.details = {{"built_with_libspnav", true}};
  try {
    const SpacenavDevice mouse(device_profile("touch"));
    c.details["found"] = true;
    c.status = CheckStatus::kOk;
    c.explanation = "a 3D mouse answers through spacenavd: --device spacemouse works";
  } catch (const Error& e) {
    c.details["found"] = false;
    c.details["error"] = e.what();
    c.status = CheckStatus::kWarn;
    c.explanation = "no 3D mouse (" + e.detail() + "): only --device spacemouse needs one";
    c.fix =
        "plug the 3D mouse in and start its daemon: apt-get install spacenavd; systemctl "
        "start spacenavd";
  }
#else
  c.details = {{"built_with_libspnav", false}, {"found", false}};
  c.status = CheckStatus::kWarn;
  c.explanation =
      "this build has no 3D mouse support (libspnav's headers were missing when it was built)";
  c.fix = "apt-get install libspnav-dev, then configure and build hapsim again";
#endif
  return c;
}

// A secure session's key folder (`--secure DIR`, docs/security.md), checked as the commands
// check it: its session name (SecurityKeyDir::session), then per identity the full check
// cyclone_security_xml makes before joining (private key 0600, certificate signed by the session
// CA and not revoked, governance and permissions signed by the permissions CA, Cyclone's
// security plugins installed).
SystemCheck check_secure_dir(const std::filesystem::path& dir, const std::string& identity) {
  SystemCheck c;
  c.name = "secure";
  c.details = {{"dir", dir.string()}};
  const std::string make_one =
      "make the keys with hapsim keys init DIR --session NAME on the key machine and copy DIR "
      "here (docs/security.md)";
  std::error_code ec;
  if (!std::filesystem::is_directory(dir, ec)) {
    c.status = CheckStatus::kFail;
    c.explanation = "--secure " + dir.string() + ": no such key folder";
    c.fix = make_one;
    return c;
  }
  std::string session;
  std::vector<std::string> names;
  try {
    const net::SecurityKeyDir keys(dir);
    session = keys.session();
    names = identity.empty() ? keys.identities() : std::vector<std::string>{identity};
  } catch (const std::exception& e) {
    c.status = CheckStatus::kFail;
    c.details["error"] = e.what();
    c.explanation = "--secure " + dir.string() + ": not a key folder: " + e.what();
    c.fix = make_one;
    return c;
  }
  c.details["session"] = session;
  std::vector<std::string> good;
  nlohmann::json bad = nlohmann::json::object();
  for (const std::string& name : names) {
    try {
      (void)net::cyclone_security_xml(dir, name, session);
      good.push_back(name);
    } catch (const std::exception& e) {
      bad[name] = e.what();
    }
  }
  c.details["identities_ok"] = good;
  c.details["identities_failed"] = bad;
  const bool has_private = std::filesystem::is_directory(dir / "private", ec);
  c.details["private_dir"] = has_private;
  const std::string keep_private =
      has_private ? "; private/ holds the CAs' keys: copy DIR to other machines without it" : "";
  if (names.empty()) {
    c.status = CheckStatus::kFail;
    c.explanation = "--secure " + dir.string() + " (session '" + session + "') holds no identity";
    c.fix = "hapsim keys add-device/add-viewer NAME on the key machine, then copy DIR here";
    return c;
  }
  if (!bad.empty()) {
    const auto& [first_name, first_error] = *bad.items().begin();
    c.status = good.empty() ? CheckStatus::kFail : CheckStatus::kWarn;
    c.explanation = "--secure " + dir.string() + " (session '" + session +
                    "'): " + std::to_string(bad.size()) + " of " + std::to_string(names.size()) +
                    " identit" + (names.size() == 1 ? "y" : "ies") + " refused; " + first_name +
                    ": " + first_error.get<std::string>();
    c.fix =
        "do what the refusal says; if the identity's files are damaged, make it again on the key "
        "machine (hapsim keys revoke NAME, then add-device/add-viewer NAME) and copy it here";
    return c;
  }
  std::string list;
  for (const std::string& n : good) {
    list += (list.empty() ? "" : ", ") + n;
  }
  c.status = CheckStatus::kOk;
  c.explanation = "--secure " + dir.string() + ": session '" + session + "', identities " + list +
                  " check out (give the commands --session " + session + ")" + keep_private;
  return c;
}

std::vector<SystemCheck> run_checks(const DoctorArgs& args) {
  std::vector<SystemCheck> checks;
  // The forked mlockall probe first, before any library starts threads of its own.
  checks.push_back(check_realtime_priority(HapticLoopOptions{}.fifo_priority));
  checks.push_back(check_memory_lock());
  checks.push_back(check_cpu_governor());
  checks.push_back(check_display());
  const bool has_display =
      checks.back().details.value("DISPLAY", nlohmann::json()).is_string() ||
      checks.back().details.value("WAYLAND_DISPLAY", nlohmann::json()).is_string();
  checks.push_back(check_offscreen_pictures(has_display));
  checks.push_back(check_dds(HAPSIM_DEFAULT_DDS_CONFIG));
  // ../shared/data beside the checkout holding scenes/, as scenes look for it.
  const std::filesystem::path beside =
      std::filesystem::absolute(HAPSIM_SCENES_DIR).lexically_normal().parent_path().parent_path() /
      "shared" / "data";
  checks.push_back(check_data_folder(args.data_dir, beside));
  checks.push_back(check_space_mouse());
  if (!args.device.empty()) {
    checks.push_back(
        check_plugin_device(*plugin_path_from_device_spec(args.device), args.driver_config));
  }
  if (!args.secure_dir.empty()) {
    checks.push_back(check_secure_dir(args.secure_dir, args.identity));
  }
  return checks;
}

void doctor(const DoctorArgs& args, bool json_given) {
  const bool json_stdout = json_given && (args.json_path.empty() || args.json_path == "-");
  // Options that cannot work are refused before any check runs.
  if (!args.device.empty()) {
    try {
      if (!plugin_path_from_device_spec(args.device)) {
        throw CommandError("--device " + args.device +
                           ": expected plugin:PATH.so (the 3D mouse is always checked)");
      }
    } catch (const Error& e) {
      throw CommandError(std::string("--device: ") + e.what());
    }
  } else if (!args.driver_config.empty()) {
    throw CommandError("--driver-config: only with --device plugin:PATH.so");
  }
  if (args.secure_dir.empty() && !args.identity.empty()) {
    throw CommandError("--identity: only with --secure DIR");
  }
  JsonOutput json_out(json_given && !json_stdout ? args.json_path : std::string());
  // With the JSON on stdout, whatever a driver or a library prints while the checks run goes to
  // stderr: stdout is the JSON alone.
  int saved_stdout = -1;
  if (json_stdout) {
    std::cout.flush();
    std::fflush(stdout);
    saved_stdout = ::dup(STDOUT_FILENO);
    ::dup2(STDERR_FILENO, STDOUT_FILENO);
  }
  std::vector<SystemCheck> checks;
  try {
    checks = run_checks(args);
  } catch (...) {
    if (saved_stdout >= 0) {
      std::fflush(stdout);
      ::dup2(saved_stdout, STDOUT_FILENO);
      ::close(saved_stdout);
    }
    throw;
  }
  const nlohmann::json j = checks_json(checks);
  if (saved_stdout >= 0) {
    std::cout.flush();
    std::fflush(stdout);
    ::dup2(saved_stdout, STDOUT_FILENO);
    ::close(saved_stdout);
    std::cout << j.dump(2) << "\n";
    std::cout.flush();
  } else {
    std::cout << format_checks_table(checks);
    std::cout.flush();
    if (json_out) {
      json_out.write(j);
    }
  }
  if (any_failed(checks)) {
    exit_status() = 1;
  }
}

}  // namespace

void add_doctor_command(CLI::App& app) {
  auto args = std::make_shared<DoctorArgs>();
  CLI::App* cmd = app.add_subcommand(
      "doctor",
      "Check this machine for hapsim: real-time priority, memory locking, CPU governor, display "
      "and EGL, Cyclone DDS, the data folder, devices; each with its fix (exit 1 if one fails)");
  CLI::Option* json =
      cmd->add_option("--json", args->json_path,
                      "Machine output: the checks as JSON on stdout, or to FILE when given")
          ->expected(0, 1);
  cmd->add_option("--device", args->device,
                  "Also open this driver plugin and report its name or the error: plugin:PATH.so");
  cmd->add_option("--driver-config", args->driver_config,
                  "plugin: the string its open() gets (e.g. a serial port)");
  cmd->add_option("--secure", args->secure_dir,
                  "Also check a secure session's key folder (hapsim keys; docs/security.md)")
      ->envname("HAPSIM_SECURE_DIR");
  cmd->add_option("--identity", args->identity,
                  "With --secure: check this identity only (default: every identity in DIR)");
  cmd->add_option("--data", args->data_dir,
                  "Check this real-data folder instead of $HAPSIM_DATA or ../shared/data");
  cmd->callback([args, json] { doctor(*args, json->count() > 0); });
}

}  // namespace hapsim::app
