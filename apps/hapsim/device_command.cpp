// `hapsim device`: the device host (docs/architecture.md#distribution). Owns the device and runs
// its 1 kHz loop on the real-time haptic thread (runtime/haptic_loop.h: absolute deadlines,
// the force watchdog, the stall supervisor); each cycle renders force from the newest local
// contact model the simulation host sent (net/device_host_client.h) and publishes the device's
// state. It waits for a simulation host (`hapsim serve`) in its session, follows it when it
// restarts, and says when it goes silent and how fast the force went to zero then.
#include "commands.h"
#include "dds_options.h"
#include "json_output.h"
#include "stop_signal.h"

#include "hapsim/core/error.h"
#include "hapsim/device/plugin_device.h"
#include "hapsim/net/legacy_force_udp.h"
#include "hapsim/net/link_shim_spec.h"
#include "hapsim/runtime/session_json.h"
#if defined(HAPSIM_WITH_SPNAV)
#include "hapsim/device/spacenav_device.h"
#endif
#include "hapsim/net/dds_domain.h"
#include "hapsim/net/device_host_client.h"
#include "hapsim/net/loaned_reader.h"
#include "hapsim/net/participant.h"
#include "hapsim/net/scene_hash.h"
#include "hapsim/net/scene_info.h"
#include "hapsim/net/security_key_dir.h"
#include "hapsim/net/served_scene.h"
#include "hapsim/rig/rig_controller.h"
#include "hapsim/runtime/deadline_clock.h"
#include "hapsim/runtime/haptic_loop.h"
#include "hapsim/scene/run_setup.h"
#include "hapsim/scene/scene_file.h"

#include <nlohmann/json.hpp>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cinttypes>
#include <cmath>
#include <csignal>
#include <cstdio>
#include <filesystem>
#include <limits>
#include <memory>
#include <optional>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

namespace hapsim::app {
namespace {

struct DeviceArgs {
  std::string device = "sim";
  std::string scene;  // sim: play this scene's script instead of the served one's
  std::string data_dir;
  DdsOptions dds;
  int device_id = 0;
  std::string name;  // several users: which of the served scene's device hosts this is
  double duration_s = std::numeric_limits<double>::quiet_NaN();  // NaN: until stopped
  std::string force_mode = "local-model";
  std::string finger_map;
  std::string json_path;
  std::string driver_config;
  std::string profile = "touch";
  std::string link_shim;
  double say_force_above_n = std::numeric_limits<double>::quiet_NaN();  // NaN: say nothing
};

// A simulation host with no model for this long is silent (its models come every millisecond).
constexpr std::int64_t kSilentAfter_ns = 200'000'000;
// Another simulation host is followed only after the one followed has been silent this long: a
// restarted serve takes seconds to load anyway, and a loaded machine can starve the DDS receive
// thread for a few hundred ms (seen: 200 ms with both cores busy) without the host being gone.
constexpr std::int64_t kOtherHostAfter_ns = 1'000'000'000;
// Models answering another host on this device id, and none answering us, for this long while
// they keep coming: the id (the name) is taken by a host the simulation follows. Longer than
// serve's 0.1 s host timeout, so a host that has just left (serve answers its last states until
// then) does not make its successor give up.
constexpr std::int64_t kTakenAfter_ns = 500'000'000;

// "--finger-map 0:2,1:3": the scene's finger 0 drives the device's finger 2, and so on; fingers
// not named keep their number.
std::array<int, kMaxFingers> parse_finger_map(const std::string& text) {
  std::array<int, kMaxFingers> map{0, 1, 2, 3, 4};
  if (text.empty()) {
    return map;
  }
  std::istringstream in(text);
  std::string pair;
  while (std::getline(in, pair, ',')) {
    int from = -1;
    int to = -1;
    char colon = 0;
    std::istringstream p(pair);
    if (!(p >> from >> colon >> to) || colon != ':' || !p.eof() || from < 0 ||
        from >= kMaxFingers || to < 0 || to >= kMaxFingers) {
      throw CommandError("--finger-map " + text +
                         ": expected SCENE:DEVICE pairs of finger "
                         "numbers 0-4, e.g. 0:2,1:3");
    }
    map[static_cast<std::size_t>(from)] = to;
  }
  return map;
}

// This host's part of a served scene: the whole of a one-user scene, or the tools of the device
// host it is named for (or the first one, when no name is given).
struct OwnPart {
  net::ServedScene scene;
  std::uint16_t device_id = 0;
  std::string name;  // "" for a one-user scene
  std::vector<std::string> other_names;
};

// Throws CommandError when --name does not fit the served scene.
OwnPart own_part(const net::SceneInfoSample& info, const DeviceArgs& args,
                 const std::array<int, kMaxFingers>& finger_map) {
  std::vector<net::ServedDeviceHost> hosts;
  try {
    hosts = net::served_device_hosts(info);
  } catch (const Error& e) {
    if (!args.name.empty()) {
      throw CommandError("--name " + args.name + ": the served scene does not read here (" +
                         e.what() + ")");
    }
  }
  OwnPart part;
  part.device_id = static_cast<std::uint16_t>(args.device_id);
  net::ServedScene& s = part.scene;
  s.scene_hash = info.scene_hash;
  s.serve_id = info.serve_id;
  s.tool_count = info.tool_count;
  std::array<int, kMaxFingers> fingers{};
  for (std::size_t t = 0; t < kMaxFingers; ++t) {
    fingers[t] = info.tool_finger[t];
  }
  if (hosts.empty() && !args.name.empty()) {
    throw CommandError("--name " + args.name + ": the served scene (" + info.scene_file +
                       ") has one user and names no device hosts: start without --name");
  }
  if (!hosts.empty()) {
    std::string names;
    for (const net::ServedDeviceHost& h : hosts) {
      names += (names.empty() ? "'" : ", '") + h.name + "'";
    }
    const auto it = args.name.empty()
                        ? hosts.begin()
                        : std::find_if(hosts.begin(), hosts.end(),
                                       [&](const auto& h) { return h.name == args.name; });
    if (it == hosts.end()) {
      throw CommandError("--name " + args.name + ": the served scene (" + info.scene_file +
                         ") has device hosts " + names + ", not this one");
    }
    part.name = it->name;
    part.device_id = it->device_id;
    s.tool_count = static_cast<std::uint16_t>(it->tool_finger.size());
    std::copy(it->tool_finger.begin(), it->tool_finger.end(), fingers.begin());
    for (const net::ServedDeviceHost& h : hosts) {
      if (h.name != part.name) {
        part.other_names.push_back(h.name);
      }
    }
  }
  for (std::size_t t = 0; t < kMaxFingers; ++t) {
    const int finger = fingers[t];
    s.tool_finger[t] = static_cast<std::int16_t>(
        finger >= 0 && finger < kMaxFingers ? finger_map[static_cast<std::size_t>(finger)] : -1);
  }
  return part;
}

// The newest SceneInfo that arrived (nullopt: none since the last call); a bad one is said once.
std::optional<net::SceneInfoSample> take_said(net::LoanedReader<hapsim_msg_SceneInfo>& in) {
  std::string refused;
  auto info = net::take_scene_info(in, &refused);
  if (!refused.empty()) {
    std::printf("ignored      a scene description from a simulation host: %s\n", refused.c_str());
  }
  return info;
}

// The device the host drives, and what to call it.
struct HostDevice {
  std::unique_ptr<Device> device;
  std::string name;
  std::optional<RunSetup> setup;  // sim: keeps the scene's world the script was aimed on
};

// The simulated device from the served scene (its script aims at that scene's surfaces).
HostDevice open_sim_device(const DeviceArgs& args, const net::SceneInfoSample& info) {
  HostDevice d;
  {
    if (args.scene.empty()) {
      d.setup.emplace(net::build_served_scene(info, DeviceChoice::scene_script(), args.data_dir));
      d.name = d.setup->device_name;
      d.device = std::move(d.setup->device);
      return d;
    }
    // Another scene's script, as asked: said once, then played.
    SceneLoadOptions load_options;
    const std::string data_dir = !args.data_dir.empty() ? args.data_dir : info.data_dir;
    if (!data_dir.empty()) {
      load_options.data_dir = data_dir;
    }
    d.setup.emplace(
        make_run_setup(load_scene(args.scene, load_options), DeviceChoice::scene_script()));
    const std::uint64_t ours = net::scene_hash(d.setup->world->content_hash());
    if (ours != info.scene_hash) {
      std::printf("note         %s differs from the served scene (hash %016" PRIx64
                  " vs %016" PRIx64 "): its script will touch what it was written for\n",
                  args.scene.c_str(), ours, info.scene_hash);
    }
    d.name = d.setup->device_name;
    d.device = std::move(d.setup->device);
    return d;
  }
}

// Every other device: opened before any simulation host is looked for, so a wrong driver is
// one line at once.
HostDevice open_device(const DeviceArgs& args) {
  HostDevice d;
  if (const auto plugin = plugin_path_from_device_spec(args.device)) {
    auto device = open_plugin_device(*plugin, args.driver_config);
    d.name = "plugin " + plugin->string();
    d.device = std::move(device);
    return d;
  }
  if (args.device.rfind("legacy-glove:", 0) == 0) {
    // An old force host in the loop: the glove renders the packets it is sent (serve
    // --legacy-force-udp), as the knee paper's force host did.
    auto glove = net::open_legacy_glove_udp(
        args.device.substr(13), device_profile("rutgers_master"), {}, "--device legacy-glove");
    d.name = "legacy force glove on UDP " + args.device.substr(13);
    d.device = std::move(glove);
    return d;
  }
  if (args.device == "spacemouse") {
#if defined(HAPSIM_WITH_SPNAV)
    d.device = std::make_unique<SpacenavDevice>(device_profile(args.profile));
    d.name = "3D mouse (spacenavd), " + args.profile + " profile: moves, renders no force";
    return d;
#else
    throw CommandError("--device spacemouse: this build has no 3D mouse support (libspnav)");
#endif
  }
  if (args.device == "mouse") {
    throw CommandError(
        "--device mouse: the mouse probe lives in the viewer (hapsim view); a device host "
        "drives sim, spacemouse, legacy-glove:PORT or plugin:PATH.so");
  }
  throw CommandError("--device " + args.device +
                     ": expected sim, spacemouse, legacy-glove:PORT or plugin:PATH.so");
}

// A served rig: this host is its master arm (net/device_host_client.h). A simulated master has
// the served world already (its script was planned on it); any other device builds it here.
void use_served_rig(const DeviceArgs& args, const net::SceneInfoSample& info, HostDevice& host,
                    net::DeviceHostOptions& options) {
  if (!host.setup) {
    SceneLoadOptions load;
    const std::string folder = !args.data_dir.empty() ? args.data_dir : info.data_dir;
    if (!folder.empty()) {
      load.data_dir = folder;
    }
    if (!parse_scene(info.scene_json, info.scene_file, load).has_rig) {
      return;
    }
    host.setup.emplace(net::build_served_scene(info, DeviceChoice::external(), args.data_dir));
  }
  const WorldDescription& world = host.setup->world->description();
  const RigController* rig = rig_controller(world);
  if (rig == nullptr) {
    return;
  }
  options.rig = std::static_pointer_cast<const RigController>(world.controller);
  const std::size_t carried = rig->description().carried_tool;
  if (carried < world.tools.size()) {
    options.rig_tool_flange_m = world.tools[carried].offset_device;
    std::printf(
        "master arm   of the served rig: tool '%s' at the slave's flange, its force felt "
        "through the master's joints\n",
        world.tools[carried].name.c_str());
  }
  if (grasps_ball(rig->description())) {
    std::printf(
        "master arm   of the served rig: its gripper's pads on the ball felt through the "
        "master's joints (what the ball weighs on them) and fingers (their grip)\n");
  } else if (carried >= world.tools.size()) {
    std::printf(
        "master arm   of the served rig: it carries no tool and grasps no ball, so nothing is "
        "felt here\n");
  }
}

struct Silence {
  double since_s = 0.0;         ///< host clock, from the device's start
  double force_before_n = 0.0;  ///< rendered with the last model
  double zero_after_ms = 0.0;
  std::uint64_t zero_after_cycles = 0;  ///< the same in the device loop's cycles
};

void run_device(const DeviceArgs& args, JsonOutput& json_out) {
  const net::ForceMode mode =
      args.force_mode == "raw" ? net::ForceMode::kRaw : net::ForceMode::kLocalModel;
  const std::array<int, kMaxFingers> finger_map = parse_finger_map(args.finger_map);
  const std::optional<net::LinkShimOptions> link =
      args.link_shim.empty() ? std::nullopt
                             : std::optional(net::parse_link_shim(args.link_shim, "--link-shim"));
  const bool sim = args.device == "sim";
  HostDevice host = sim ? HostDevice{} : open_device(args);
  net::DdsDomain domain(args.dds.domain, HAPSIM_DEFAULT_DDS_CONFIG, args.dds.network());
  net::Participant participant(args.dds.domain, args.dds.session);
  net::LoanedReader<hapsim_msg_SceneInfo> info_in(participant);
  const std::atomic<bool>& stop = install_stop_signals();

  std::printf("device host  session '%s' (partition %s, domain %d), config %s\n",
              args.dds.session.c_str(), participant.partition().c_str(), args.dds.domain,
              domain.config().c_str());
  std::printf("waiting      for a simulation host (hapsim serve SCENE --session %s)\n",
              args.dds.session.c_str());
  std::fflush(stdout);
  std::optional<net::SceneInfoSample> info;
  // --duration bounds the wait too: a scripted `hapsim device --duration 2` with no serve running
  // used to wait forever.
  const auto waiting_since = std::chrono::steady_clock::now();
  const auto waited_s = [&] {
    return std::chrono::duration<double>(std::chrono::steady_clock::now() - waiting_since).count();
  };
  while (!info && !stop.load(std::memory_order_relaxed)) {
    info = take_said(info_in);
    if (!info && !std::isnan(args.duration_s) && waited_s() > args.duration_s) {
      char text[240];
      std::snprintf(text, sizeof text,
                    "no simulation host appeared within --duration %g s on session '%s' (start "
                    "hapsim serve SCENE --session %s first)",
                    args.duration_s, args.dds.session.c_str(), args.dds.session.c_str());
      throw CommandError(text);
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
  }
  if (!info) {
    std::printf("stopped      before a simulation host appeared\n");
    json_out.write_failure("stopped by " + std::string(stop_signal_name()) +
                           " before a simulation host appeared");
    exit_status() = stopped_by_signal_status();
    return;
  }
  const OwnPart part = own_part(*info, args, finger_map);
  std::printf("serving      %s (hash %016" PRIx64 "), %u tool(s) for this host\n",
              info->scene_file.c_str(), info->scene_hash,
              static_cast<unsigned>(part.scene.tool_count));
  if (!part.name.empty()) {
    std::string others;
    for (const std::string& other : part.other_names) {
      others += (others.empty() ? "'" : ", '") + other + "'";
    }
    std::printf("user         '%s' (device id %u)%s%s%s\n", part.name.c_str(),
                static_cast<unsigned>(part.device_id),
                others.empty() ? "" : "; also in the world: ", others.c_str(),
                args.name.empty() ? " (the scene's first device host: --name NAME chooses)" : "");
  }
  if (sim) {
    host = open_sim_device(args, *info);
    if (!part.name.empty() && part.device_id != info->device_id && args.scene.empty()) {
      std::printf(
          "note         the served scene's script moves its first user's tools; '%s' "
          "plays it too (give this host its own with --scene FILE)\n",
          part.name.c_str());
    }
  }
  const DeviceProfile& profile = host.device->profile();

  net::DeviceHostOptions options;
  options.device_id = part.device_id;
  options.mode = mode;
  // A glove has no tip actuator (its tip rating is 0): its tools are on fingers, and a tool on
  // none is held to the finger rating too (the device's own clamp has the last word).
  if (!(profile.max_force_n > 0.0) && !(profile.max_finger_force_n > 0.0)) {
    throw Error("device " + host.name,
                "its profile '" + profile.name + "' rates no force (tip and fingers 0 N)");
  }
  options.max_finger_force_n = profile.max_finger_force_n;
  options.render.max_force_n =
      profile.max_force_n > 0.0 ? profile.max_force_n : profile.max_finger_force_n;
  if (link) {
    options.link = link;
    std::printf("link shim    on the local models received: %s\n", args.link_shim.c_str());
  }
  if (profile.max_damping_n_s_per_m > 0.0) {
    options.passivity.max_damping_n_s_per_m = profile.max_damping_n_s_per_m;
  }
  use_served_rig(args, *info, host, options);
  net::DeviceHostClient client(participant, options);
  client.set_scene(part.scene);

  HapticLoopOptions loop_options;
  loop_options.period_s = 0.001;
  if (!std::isnan(args.duration_s)) {
    loop_options.max_cycles = static_cast<std::uint64_t>(std::llround(args.duration_s * 1000.0));
  }
  HapticLoop loop(*host.device, client, loop_options);
  char rating[48];
  if (profile.max_force_n > 0.0) {
    std::snprintf(rating, sizeof rating, "%.1f N", profile.max_force_n);
  } else {
    std::snprintf(rating, sizeof rating, "%.1f N per finger", profile.max_finger_force_n);
  }
  std::printf("device       %s, rated %s; force mode %s%s\n", host.name.c_str(), rating,
              net::to_string(mode),
              mode == net::ForceMode::kRaw
                  ? " (the paper's raw forces: unsafe beyond a few ms of delay, for comparison)"
                  : " (rendered at the device's own position)");
  std::fflush(stdout);

  const std::int64_t start_ns = monotonic_ns();
  const auto host_s = [start_ns](std::int64_t ns) {
    return static_cast<double>(ns - start_ns) * 1e-9;
  };
  loop.start();
  bool sim_alive = false;
  std::uint64_t serve_id = info->serve_id;
  std::uint64_t joins = 0;
  std::optional<Silence> pending_silence;  // silent, force not yet reported at zero
  std::vector<Silence> silences;
  bool above_said = false;  // --say-force-above: said once per rise, again after a fall below
  // Another simulation host on the session (a second serve, or the followed one restarted):
  // followed only once the one joined first has gone silent, never while it answers.
  std::optional<net::SceneInfoSample> other;
  std::uint64_t other_said = serve_id;
  std::uint64_t other_hosts = 0;
  bool taken = false;
  std::uint64_t other_host_models = 0;  // models answering another host on our id, so far
  std::int64_t other_host_since_ns = 0;
  std::int64_t other_host_last_ns = 0;
  while (loop.running() && !stop.load(std::memory_order_relaxed)) {
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
    if (auto fresh = take_said(info_in); fresh && fresh->serve_id != serve_id) {
      other = std::move(fresh);
    }
    const net::DeviceHostStatus s = client.status();
    const std::int64_t now_ns = monotonic_ns();
    const bool alive = s.last_model_ns != 0 && now_ns - s.last_model_ns < kSilentAfter_ns;
    // Taken: the simulation answers another host on this device id (the same name), never us.
    if (s.models_accepted == 0 && s.models_other_device_host > 0) {
      if (s.models_other_device_host != other_host_models) {
        other_host_models = s.models_other_device_host;
        other_host_last_ns = now_ns;
        other_host_since_ns = other_host_since_ns == 0 ? now_ns : other_host_since_ns;
      }
      if (now_ns - other_host_since_ns >= kTakenAfter_ns &&
          now_ns - other_host_last_ns < kSilentAfter_ns) {
        taken = true;
        break;
      }
    }
    if (other && (s.last_model_ns == 0 || now_ns - s.last_model_ns >= kOtherHostAfter_ns)) {
      serve_id = other->serve_id;
      std::printf("simulation   host restarted: %s (hash %016" PRIx64 ")%s\n",
                  other->scene_file.c_str(), other->scene_hash,
                  other->scene_hash != info->scene_hash ? ", another scene" : "");
      std::fflush(stdout);
      std::optional<OwnPart> next;
      try {
        next = own_part(*other, args, finger_map);
      } catch (const CommandError& e) {
        std::printf("simulation   its scene has no place for this host (%s): rendering nothing\n",
                    e.what());
      }
      if (next && next->device_id != part.device_id) {
        std::printf(
            "simulation   its scene gives this host device id %u, not %u: rendering "
            "nothing (restart hapsim device)\n",
            static_cast<unsigned>(next->device_id), static_cast<unsigned>(part.device_id));
        next.reset();
      }
      if (!next) {
        next = part;
        next->scene = net::ServedScene{};
        next->scene.scene_hash = other->scene_hash;
        next->scene.serve_id = other->serve_id;  // no tools: nothing rendered
      }
      std::fflush(stdout);
      client.set_scene(next->scene);
      other.reset();
    } else if (other && other->serve_id != other_said) {
      other_said = other->serve_id;
      ++other_hosts;
      std::printf("simulation   another host on the session (%s, hash %016" PRIx64
                  ") at %.3f s: not followed while the one joined first answers\n",
                  other->scene_file.c_str(), other->scene_hash, host_s(now_ns));
      std::fflush(stdout);
    }
    if (alive && !sim_alive) {
      ++joins;
      std::printf("simulation   host %s at %.3f s: rendering its local models\n",
                  joins == 1 ? "answering" : "back", host_s(now_ns));
      std::fflush(stdout);
      pending_silence.reset();
    } else if (!alive && sim_alive) {
      pending_silence = Silence{host_s(s.last_model_ns), s.force_at_last_model_n, 0.0, 0};
    }
    sim_alive = alive;
    if (!std::isnan(args.say_force_above_n)) {
      const bool above = s.force_n > args.say_force_above_n;
      if (above && !above_said) {
        std::printf("force        above %.2f N at %.3f s (%.3f N)\n", args.say_force_above_n,
                    host_s(now_ns), s.force_n);
        std::fflush(stdout);
      }
      above_said = above;
    }
    if (pending_silence && s.force_n == 0.0) {
      // The force reached zero: how long after the last model arrived.
      pending_silence->zero_after_ms =
          std::max(0.0, static_cast<double>(s.last_force_ns - s.last_model_ns) * 1e-6);
      pending_silence->zero_after_cycles =
          s.last_force_cycle > s.last_model_cycle ? s.last_force_cycle - s.last_model_cycle : 0;
      std::printf(
          "simulation   host silent since %.3f s: force %.3f N went to zero %.0f ms after "
          "its last model; the device loop keeps running and waits for it\n",
          pending_silence->since_s, pending_silence->force_before_n,
          pending_silence->zero_after_ms);
      std::fflush(stdout);
      silences.push_back(*pending_silence);
      pending_silence.reset();
    }
  }
  loop.stop();
  if (taken) {
    const std::string who = part.name.empty() ? "device id " + std::to_string(part.device_id)
                                              : "device host '" + part.name + "' (device id " +
                                                    std::to_string(part.device_id) + ")";
    throw CommandError(who + " is taken on session '" + args.dds.session +
                       "': the simulation host answers another device host there (stop it, or "
                       "start this one with another --name)");
  }

  const HapticLoopStatus st = loop.status();
  const net::DeviceHostStatus s = client.status();
  const RealtimeSummary rt = realtime_summary(st, 0);
  std::printf("ran          %" PRIu64 " cycles in %.3f s\n", st.cycles, st.elapsed_s);
  std::printf("%s", format_realtime_summary(rt).c_str());
  std::printf("rendered     peak %.3f N; %" PRIu64 " rate-limited cycles, %" PRIu64
              " clamped by the watchdog; passivity controller acted in %" PRIu64
              " cycles (%.3f mJ taken out)\n",
              s.peak_force_n, s.rate_limited_cycles, st.clamped_cycles, s.passivity_cycles,
              s.passivity_dissipated_j * 1e3);
  if (options.rig) {
    std::printf(
        "master arm   peak joint torque %.3f N m (the force at the slave's tool through its Jt), "
        "peak grasp %.3f N\n",
        s.peak_joint_torque_nm, s.peak_grasp_force_n);
    if (s.held_cycles > 0) {
      std::printf("master arm   held the ball %" PRIu64
                  " cycles, feeling %.3f N at the slave's tool on average\n",
                  s.held_cycles, s.mean_held_force_n);
    }
  }
  std::printf("models       %" PRIu64 " rendered (%" PRIu64 " answering the script, not us);",
              s.models_accepted, s.models_not_ours);
  for (std::size_t v = 0; v < net::kSampleVerdicts; ++v) {
    std::printf(" %s %" PRIu64 "%s", net::verdict_name(static_cast<net::SampleVerdict>(v)),
                s.verdicts[v], v + 1 < net::kSampleVerdicts ? "," : "\n");
  }
  std::printf("states       %" PRIu64
              " published; round trip state -> model p50 %.0f us, p99 %.0f "
              "us, max %.0f us\n",
              s.states_published, s.round_trip_us.p50, s.round_trip_us.p99, s.round_trip_us.max);
  if (json_out) {
    nlohmann::json j;
    j["device"] = host.name;
    j["session"] = args.dds.session;
    j["force_mode"] = net::to_string(mode);
    j["cycles"] = st.cycles;
    j["realtime"] = realtime_json(rt);
    j["peak_force_n"] = s.peak_force_n;
    if (options.rig) {
      j["peak_joint_torque_nm"] = s.peak_joint_torque_nm;
      j["peak_grasp_force_n"] = s.peak_grasp_force_n;
      j["mean_held_force_n"] = s.mean_held_force_n;
      j["held_cycles"] = s.held_cycles;
    }
    j["rate_limited_cycles"] = s.rate_limited_cycles;
    j["passivity"] = {{"cycles_acted", s.passivity_cycles},
                      {"dissipated_j", s.passivity_dissipated_j}};
    j["clamped_cycles"] = st.clamped_cycles;
    j["models_rendered"] = s.models_accepted;
    j["models_not_ours"] = s.models_not_ours;
    j["models_for_another_host"] = s.models_other_device_host;
    if (!part.name.empty()) {
      j["name"] = part.name;
      j["device_id"] = part.device_id;
    }
    for (std::size_t v = 0; v < net::kSampleVerdicts; ++v) {
      j["models"][net::verdict_name(static_cast<net::SampleVerdict>(v))] = s.verdicts[v];
    }
    j["states_published"] = s.states_published;
    j["round_trip_us"] = {
        {"p50", s.round_trip_us.p50}, {"p99", s.round_trip_us.p99}, {"max", s.round_trip_us.max}};
    j["simulation_joins"] = joins;
    j["other_simulation_hosts"] = other_hosts;  // seen while the followed one answered
    j["silences"] = nlohmann::json::array();
    for (const Silence& silence : silences) {
      j["silences"].push_back({{"since_s", silence.since_s},
                               {"force_before_n", silence.force_before_n},
                               {"force_zero_after_ms", silence.zero_after_ms},
                               {"force_zero_after_cycles", silence.zero_after_cycles}});
    }
    if (*stop_signal_name() != '\0') {
      j["stopped_by"] = stop_signal_name();
    }
    json_out.write(j);
  }
  exit_status() = with_signal_status(exit_status());
}

void run_device(const DeviceArgs& args) {
  JsonOutput json_out(args.json_path);
  with_failure_json(json_out, [&] { run_device(args, json_out); });
}

}  // namespace

void add_device_command(CLI::App& app) {
  auto args = std::make_shared<DeviceArgs>();
  CLI::App* cmd = app.add_subcommand(
      "device",
      "Device host: run a device's 1 kHz loop, rendering force from the local contact models of "
      "a simulation host (hapsim serve) in the same session");
  cmd->add_option("--device", args->device,
                  "sim (the served scene's own script, or --scene's; default), spacemouse (a 3D "
                  "mouse via spacenavd), legacy-glove:[ADDRESS:]PORT (the knee paper's force "
                  "packets from serve --legacy-force-udp) or plugin:PATH.so (a driver, "
                  "include/hapsim/device_driver.h)");
  cmd->add_option("--driver-config", args->driver_config,
                  "plugin: the string its open() gets (e.g. a serial port)");
  cmd->add_option("--profile", args->profile,
                  "spacemouse: the device profile whose limits apply (default touch)");
  cmd->add_option("--scene", args->scene,
                  "sim: play this scene's script instead of the served scene's");
  cmd->add_option("--data", args->data_dir,
                  "sim: the scene's data folder (default: the simulation host's)");
  CLI::Option* id_option =
      cmd->add_option("--device-id", args->device_id, "This device's id (default 0)")
          ->check(CLI::Range(0, 65535));
  cmd->add_option("--name", args->name,
                  "Several users in one world: which of the served scene's device hosts this is "
                  "(its tools' \"device_host\"; default: the first); a name another host holds "
                  "is refused")
      ->excludes(id_option);
  cmd->add_option("--duration", args->duration_s,
                  "Seconds to run the loop, and the longest wait for a simulation host "
                  "(default: until stopped)")
      ->check(positive_seconds());
  cmd->add_option("--force-mode", args->force_mode,
                  "local-model (default) or raw (the paper's raw forces: unsafe beyond a few ms "
                  "of delay; for comparison)")
      ->check(CLI::IsMember({"local-model", "raw"}));
  cmd->add_option("--finger-map", args->finger_map,
                  "Which device finger each scene finger drives, e.g. 0:2,1:3");
  cmd->add_option("--link-shim", args->link_shim,
                  "Pass the local models received through a simulated link: "
                  "delay_ms=D,jitter_ms=J,loss=L,outage_at_s=T,outage_s=S,seed=N (no root, no "
                  "netem)");
  cmd->add_option("--say-force-above", args->say_force_above_n,
                  "Print a line each time the rendered force rises above this many newtons "
                  "(for an operator or a script watching the device host)")
      ->check(CLI::PositiveNumber);
  cmd->add_option("--json", args->json_path, "Write the summary as JSON");
  add_dds_options(cmd, args->dds, net::SecurityRole::kDevice);
  cmd->callback([args] {
    (void)net::session_partition(args->dds.session);
    // Secure, a named host joins as the device identity of its name when DIR has one (hapsim
    // keys add-device trainee), so each user's device is its own identity.
    if (args->dds.secure() && args->dds.identity.empty() && !args->name.empty()) {
      const net::SecurityKeyDir keys(args->dds.secure_dir);
      std::error_code ec;
      if (std::filesystem::is_directory(keys.identity(args->name), ec) &&
          net::read_role(keys, args->name) == net::role_name(net::SecurityRole::kDevice)) {
        args->dds.identity = args->name;
      }
    }
    run_device(*args);
  });
}

}  // namespace hapsim::app
