// `hapsim serve SCENE`: the simulation host (docs/architecture.md#distribution). Steps the
// scene's world on the real-time haptic loop at --rate, and on the session's DDS partition
//  * publishes, per tool and step, the local contact model a device host renders from
//    (net/model_publisher.h);
//  * lets a device host's gated states drive the world while they keep coming, the scene's own
//    script otherwise (net/remote_device.h), and says when a host joins or goes silent;
//  * publishes what it serves (SceneInfo: the scene's text and hash; a late joiner gets it) and,
//    at --view-rate, what a viewer draws (ViewState, net/view_state_codec.h).
// At the end it prints the same summary as `hapsim run` (contacts and peak force per segment,
// forces per tool, safety) plus what went over the network, and --json writes it with the same
// keys as `hapsim run --json`, so a served run and a one-process run compare key by key.
// --record FILE records every stepped cycle as `hapsim run --record` does (the same recorder,
// flushed every 100 ms off the haptic thread); with --secure the finished recording is signed
// (FILE.sig, net/recording_signature.h) so `hapsim assess --verify` can tell it is this serve's.
#include "commands.h"
#include "dds_options.h"
#include "json_output.h"
#include "stop_signal.h"

#include "hapsim/device/absent_device.h"
#include "hapsim/net/command_receiver.h"
#include "hapsim/net/dds_domain.h"
#include "hapsim/net/legacy_force_udp.h"
#include "hapsim/net/link_shim_spec.h"
#include "hapsim/net/model_publisher.h"
#include "hapsim/net/participant.h"
#include "hapsim/net/recording_signature.h"
#include "hapsim/net/remote_device.h"
#include "hapsim/net/scene_hash.h"
#include "hapsim/net/scene_info.h"
#include "hapsim/net/topic_writer.h"
#include "hapsim/net/view_state_codec.h"
#include "hapsim/runtime/session.h"
#include "hapsim/runtime/session_json.h"
#include "hapsim/scene/run_setup.h"
#include "hapsim/scene/scene_file.h"

#include <nlohmann/json.hpp>

#include <algorithm>
#include <array>
#include <atomic>
#include <cctype>
#include <chrono>
#include <cinttypes>
#include <cmath>
#include <csignal>
#include <cstdio>
#include <fstream>
#include <iostream>
#include <iterator>
#include <limits>
#include <memory>
#include <mutex>
#include <numeric>
#include <optional>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

namespace hapsim::app {
namespace {

struct ServeArgs {
  std::string scene;
  double rate_hz = 1000.0;
  double duration_s = std::numeric_limits<double>::quiet_NaN();  // NaN: until stopped
  DdsOptions dds;
  int device_id = 0;
  std::string data_dir;
  bool wait_for_device = false;
  double view_rate_hz = 30.0;
  std::string legacy_force_udp;
  double lockstep_us = 800.0;
  std::string link_shim;
  std::string json_path;
  std::string record_path;
  bool insecure = false;  // plain DDS on a network interface, said out loud
};

// Longest a served run may be asked to last; "until stopped" is this long.
constexpr double kUntilStopped_s = 365.0 * 24.0 * 3600.0;

std::string read_text(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) {
    throw CommandError(path + ": cannot read the scene file");
  }
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

// Off the haptic thread: publishes the newest snapshot for viewers at the view rate, acts on the
// commands viewers and operators send (net/command_receiver.h) and prints every change of who
// drives the world and every command, until `done`.
// One device host of the served world: its link and what the summary calls it.
struct ServedHost {
  std::string name;  // the scene's device_host name ("" for a one-user scene)
  std::uint16_t device_id = 0;
  std::unique_ptr<Device> absent;  // the fallback of another user's device (k > 0)
  std::unique_ptr<net::RemoteDevice> link;
};

// "device host" or "device host 'trainee'", for the lines that name one.
std::string host_label(const ServedHost& host) {
  return host.name.empty() ? std::string("device host") : "device host '" + host.name + "'";
}

class ServeMonitor {
 public:
  ServeMonitor(const net::Participant& participant, const World& world, std::uint64_t hash,
               std::uint64_t serve_id, const std::vector<ServedHost>& hosts, double view_rate_hz)
      : views_out_(participant),
        encoder_(world),
        commands_(participant, world, hash, serve_id),
        hash_(hash),
        serve_id_(serve_id),
        hosts_(hosts),
        device_(*hosts.front().link),
        period_(std::chrono::microseconds(static_cast<std::int64_t>(1e6 / view_rate_hz))) {
    for (const MaterialDescription& m : world.description().materials) {
      material_names_.push_back(m.name);
    }
  }

  /// The loop's client, or null once the loop stopped (returns once the monitor let go of it).
  void set_client(WorldHapticClient* client) {
    const std::lock_guard<std::mutex> lock(snapshots_mutex_);
    if (client == nullptr && client_ != nullptr) {
      refused_materials_ = client_->refused_material_changes();
    }
    client_ = client;
  }

  /// The loop's snapshots, or null when they go away (returns once the monitor let go of them).
  void set_snapshots(TripleBuffer<WorldSnapshot>* snapshots) {
    const std::lock_guard<std::mutex> lock(snapshots_mutex_);
    snapshots_ = snapshots;
  }

  void start() {
    thread_ = std::thread([this] { run(); });
  }
  void stop() {
    done_.store(true, std::memory_order_relaxed);
    if (thread_.joinable()) {
      thread_.join();
    }
  }
  [[nodiscard]] std::uint64_t views_published() const { return views_; }
  /// After stop(): the commands' verdicts, and material changes the world refused.
  [[nodiscard]] const net::VerdictCounts& command_verdicts() const { return commands_.counts(); }
  [[nodiscard]] std::uint64_t refused_material_changes() const { return refused_materials_; }

 private:
  void run() {
    const auto start = std::chrono::steady_clock::now();
    std::vector<std::uint64_t> transitions;
    std::vector<bool> other_said(hosts_.size(), false);
    for (const ServedHost& host : hosts_) {
      transitions.push_back(host.link->transitions());
    }
    while (!done_.load(std::memory_order_relaxed)) {
      std::this_thread::sleep_for(period_);
      const double t_s =
          std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
      for (std::size_t k = 0; k < hosts_.size(); ++k) {
        const net::RemoteDevice& link = *hosts_[k].link;
        if (link.transitions() != transitions[k]) {
          transitions[k] = link.transitions();
          const char* silent = k == 0 ? "silent: the scene's script drives the world (the device "
                                        "host stopped or its link is down)"
                                      : "silent: its tools are held, with no force (the device "
                                        "host stopped or its link is down)";
          std::printf("%-12s %s at %.3f s\n", host_label(hosts_[k]).c_str(),
                      link.host_driving() ? "joined: its states drive the world" : silent, t_s);
          std::fflush(stdout);
        }
        if (link.other_host_states() > 0 && !other_said[k]) {
          other_said[k] = true;  // once: a second host keeps sending until it gives up
          std::printf(
              "%-12s claimed by a second host (device id %u) at %.3f s: refused while "
              "the first one drives it\n",
              host_label(hosts_[k]).c_str(), static_cast<unsigned>(hosts_[k].device_id), t_s);
          std::fflush(stdout);
        }
      }
      const std::lock_guard<std::mutex> lock(snapshots_mutex_);
      commands_.poll(client_, [&](const net::CommandEvent& event) {
        // Each refusal reason said once (a flood of bad commands must not flood the output);
        // the counts are in the summary.
        const auto v = static_cast<std::size_t>(event.verdict);
        if (event.verdict == net::SampleVerdict::kAccepted || !refusal_said_[v]) {
          refusal_said_[v] = event.verdict != net::SampleVerdict::kAccepted;
          std::printf("command      %s at %.3f s\n",
                      net::describe_command_event(event, material_names_).c_str(), t_s);
          std::fflush(stdout);
        }
      });
      const bool paused = client_ != nullptr && client_->paused();
      if (snapshots_ != nullptr && (snapshots_->update() || paused != view_paused_)) {
        view_paused_ = paused;
        views_ += views_out_.write(encoder_.encode(snapshots_->read_slot(), hash_, serve_id_,
                                                   device_.host_driving(), paused))
                      ? 1
                      : 0;
      }
    }
  }

  net::TopicWriter<hapsim_msg_ViewState> views_out_;
  net::ViewStateEncoder encoder_;
  net::CommandReceiver commands_;
  std::vector<std::string> material_names_;
  std::array<bool, net::kSampleVerdicts> refusal_said_{};
  WorldHapticClient* client_ = nullptr;  // guarded by snapshots_mutex_
  bool view_paused_ = false;
  std::uint64_t refused_materials_ = 0;
  std::uint64_t hash_;
  std::uint64_t serve_id_;
  const std::vector<ServedHost>& hosts_;
  const net::RemoteDevice& device_;  // device 0's: its host drives the step
  std::chrono::microseconds period_;
  std::mutex snapshots_mutex_;  // the monitor's thread and run_session's (off the haptic one)
  TripleBuffer<WorldSnapshot>* snapshots_ = nullptr;
  std::atomic<bool> done_{false};
  std::uint64_t views_ = 0;
  std::thread thread_;
};

void serve(const ServeArgs& args, JsonOutput& json_out) {
  if (!(args.rate_hz >= 10.0 && args.rate_hz <= 10'000.0)) {
    throw CommandError("--rate " + std::to_string(args.rate_hz) + ": expected 10 to 10000 Hz");
  }
  if (!(args.view_rate_hz >= 1.0 && args.view_rate_hz <= 240.0)) {
    throw CommandError("--view-rate " + std::to_string(args.view_rate_hz) +
                       ": expected 1 to 240 Hz");
  }
  const std::optional<net::LinkShimOptions> link =
      args.link_shim.empty() ? std::nullopt
                             : std::optional(net::parse_link_shim(args.link_shim, "--link-shim"));
  SceneLoadOptions load_options;
  if (!args.data_dir.empty()) {
    load_options.data_dir = args.data_dir;
  }
  RunSetup setup =
      make_run_setup(load_scene(args.scene, load_options), DeviceChoice::scene_script());
  World& world = *setup.world;
  // A recording replays at the scene's run.dt_s (hapsim run --replay): serve must step at it.
  if (!args.record_path.empty() && std::abs(args.rate_hz * setup.scene.run.dt_s - 1.0) > 1e-9) {
    char text[160];
    std::snprintf(text, sizeof text,
                  ": a recording replays at the scene's run.dt_s, %g s: serve it at --rate %g, "
                  "not %g",
                  setup.scene.run.dt_s, 1.0 / setup.scene.run.dt_s, args.rate_hz);
    throw CommandError("--record " + args.record_path + text);
  }
  // Opened before anything is served, so a bad path fails first; flushed every 100 ms off the
  // haptic thread by run_session, as `hapsim run --record` is.
  std::unique_ptr<SessionRecorder> recorder;
  if (!args.record_path.empty()) {
    try {
      recorder = make_session_recorder(args.record_path, world, args.scene);
    } catch (const Error& e) {
      throw CommandError("--record " + args.record_path + ": " + e.detail());
    }
  }
  const std::uint64_t hash = net::scene_hash(world.content_hash());
  const std::uint64_t serve_id = net::draw_serve_id();
  const auto device_id = static_cast<std::uint16_t>(args.device_id);
  // Several users: one device host per name the scene's tools give, with ids from --device-id
  // on in the scene's order (hapsim device --name NAME finds its own).
  const std::vector<std::string>& host_names = world.description().device_hosts;
  const std::size_t host_count = std::max<std::size_t>(1, host_names.size());
  if (args.device_id + host_count - 1 > 65535) {
    throw CommandError("--device-id " + std::to_string(args.device_id) + ": the scene's " +
                       std::to_string(host_count) + " device hosts need ids up to 65535");
  }
  if (host_count > 1 && !args.record_path.empty()) {
    throw CommandError("--record " + args.record_path + ": " + args.scene + " has " +
                       std::to_string(host_count) +
                       " device hosts, and a recording holds one device's input (record a "
                       "one-user scene)");
  }
  // Per device, the tools it moves (models for the first kMaxFingers: one key per finger).
  std::vector<std::vector<std::size_t>> host_tools(host_count);
  for (std::size_t t = 0; t < world.description().tools.size(); ++t) {
    host_tools[static_cast<std::size_t>(world.description().tools[t].device)].push_back(t);
  }
  for (std::size_t k = 0; k < host_count; ++k) {
    if (host_tools[k].size() > static_cast<std::size_t>(kMaxFingers)) {
      std::printf(
          "note         %zu tools on %s: models are served for the first %d (one per "
          "finger)\n",
          host_tools[k].size(), host_names.empty() ? "the device" : host_names[k].c_str(),
          kMaxFingers);
      host_tools[k].resize(static_cast<std::size_t>(kMaxFingers));
    }
  }
  const std::size_t tools = host_tools[0].size();  // device 0's: what SceneInfo describes

  net::DdsDomain domain(args.dds.domain, HAPSIM_DEFAULT_DDS_CONFIG, args.dds.network());
  // A secure serve signs what it records, as its identity: its key is checked now, not after the
  // session.
  std::optional<net::RecordingSigner> signer;
  if (!args.record_path.empty() && args.dds.secure()) {
    signer.emplace(net::SecurityKeyDir(args.dds.secure_dir), args.dds.identity_name());
  }
  net::Participant participant(args.dds.domain, args.dds.session);
  std::vector<ServedHost> hosts(host_count);
  for (std::size_t k = 0; k < host_count; ++k) {
    ServedHost& host = hosts[k];
    host.name = host_names.empty() ? std::string() : host_names[k];
    host.device_id = static_cast<std::uint16_t>(device_id + k);
    if (k > 0) {
      host.absent = std::make_unique<AbsentDevice>(*setup.profile);
    }
    host.link = std::make_unique<net::RemoteDevice>(participant, host.device_id, hash,
                                                    k == 0 ? *setup.device : *host.absent);
  }
  for (std::size_t k = 0; k < host_count && host_count > 1; ++k) {
    std::vector<std::uint16_t> siblings;
    for (std::size_t j = 0; j < host_count; ++j) {
      if (j != k) {
        siblings.push_back(hosts[j].device_id);
      }
    }
    hosts[k].link->set_sibling_device_ids(siblings);
  }
  net::RemoteDevice& remote = *hosts[0].link;
  double lockstep_s = args.lockstep_us * 1e-6;
  if (lockstep_s > 0.9 / args.rate_hz) {
    lockstep_s = 0.9 / args.rate_hz;
    std::printf(
        "note         --lockstep-us %.0f is longer than the cycle allows at %.0f Hz: "
        "%.0f us\n",
        args.lockstep_us, args.rate_hz, lockstep_s * 1e6);
  }
  if (link) {
    for (ServedHost& host : hosts) {
      host.link->set_link_shim(*link);
    }
    if (lockstep_s > 0.0) {
      lockstep_s = 0.0;
      std::printf(
          "note         --link-shim: no lockstep (the states it delays are the ones "
          "lockstep would wait for)\n");
    }
    std::printf("link shim    on the device states received: %s\n", args.link_shim.c_str());
  }
  remote.set_lockstep_wait(lockstep_s);
  std::vector<net::RemoteDevice*> links;
  for (ServedHost& host : hosts) {
    links.push_back(host.link.get());
  }
  net::LocalModelPublisher publisher(participant, world, links, device_id, hash);
  std::unique_ptr<net::LegacyForceUdpSender> legacy;
  if (!args.legacy_force_udp.empty()) {
    const DeviceProfile& profile = *setup.profile;
    if (profile.finger_count < 1 || !(profile.max_finger_force_n > 0.0)) {
      throw CommandError("--legacy-force-udp: the legacy packet carries finger forces; " +
                         args.scene + "'s device (" + profile.name + ") has no force fingers");
    }
    legacy = std::make_unique<net::LegacyForceUdpSender>(args.legacy_force_udp);
    publisher.send_legacy_forces(legacy.get(), profile.max_finger_force_n);
    std::printf(
        "legacy       one force packet per cycle to %s:%u (4 fingers, 0-10000 = 0-%.1f N)\n",
        legacy->destination().host.c_str(), static_cast<unsigned>(legacy->destination().port),
        profile.max_finger_force_n);
  }
  ServeMonitor monitor(participant, world, hash, serve_id, hosts, args.view_rate_hz);

  // What this host serves, once: reliable and transient-local, so a late joiner gets it.
  net::SceneInfoSample info;
  info.scene_hash = hash;
  info.serve_id = serve_id;
  info.rate_hz = args.rate_hz;
  info.device_id = device_id;
  info.tool_count = static_cast<std::uint16_t>(tools);
  for (std::size_t t = 0; t < tools; ++t) {
    info.tool_finger[t] =
        static_cast<std::int16_t>(world.description().tools[host_tools[0][t]].finger);
  }
  info.scene_file = args.scene;
  info.scene_json = read_text(args.scene);
  info.data_dir = args.data_dir;
  net::TopicWriter<hapsim_msg_SceneInfo> info_out(participant);
  if (!info_out.write(net::scene_info_message(info))) {
    throw CommandError("could not publish the scene on DDS");
  }

  std::printf("serve        %s, %zu tool(s), scene hash %016" PRIx64 ", at %.0f Hz\n",
              args.scene.c_str(), world.description().tools.size(), hash, args.rate_hz);
  for (std::size_t k = 0; k < host_count && !host_names.empty(); ++k) {
    std::string tool_names;
    for (const std::size_t t : host_tools[k]) {
      tool_names += (tool_names.empty() ? "" : ", ") + world.description().tools[t].name;
    }
    std::printf("user         '%s': device id %u, tools %s (hapsim device --name %s)%s\n",
                hosts[k].name.c_str(), static_cast<unsigned>(hosts[k].device_id),
                tool_names.c_str(), hosts[k].name.c_str(),
                k == 0 ? "; the scene's script moves them until its host joins" : "");
  }
  std::printf("dds          domain %d, session '%s' (partition %s), config %s\n", args.dds.domain,
              args.dds.session.c_str(), participant.partition().c_str(), domain.config().c_str());
  if (domain.secure()) {
    std::printf(
        "security     SECURE: DDS Security as identity '%s' of %s (authenticated, access "
        "controlled per role, encrypted)\n",
        args.dds.identity_name().c_str(), args.dds.secure_dir.c_str());
  } else {
    std::printf("security     PLAIN: no --secure, anyone who reaches %s may join the session\n",
                args.dds.interface.empty() ? "this machine's loopback" : "this network");
  }
  std::fflush(stdout);

  const std::atomic<bool>& stop = install_stop_signals();
  // After finish_session_recording: says where the recording went and, secure, signs it; false
  // (with one line said) when either was not written in full.
  const auto report_recording = [&](const SessionSummary& summary) {
    if (!recorder) {
      return true;
    }
    std::printf("recorded     %s (%zu frames)\n", args.record_path.c_str(),
                recorder->frames_written());
    bool ok = summary.recording_error.empty();
    if (!ok) {
      std::printf("FAILED: the recording stopped early: %s\n", summary.recording_error.c_str());
    }
    if (signer) {
      try {
        const net::RecordingStatement signed_as =
            signer->sign(args.record_path, summary.steps, remote.cycles_driven());
        std::printf("signed       %s (identity '%s' of session '%s', sha256 %.16s...)\n",
                    net::recording_signature_path(args.record_path).c_str(),
                    signed_as.identity.c_str(), signed_as.session.c_str(),
                    signed_as.sha256_hex.c_str());
      } catch (const Error& e) {
        std::printf("FAILED: the recording's signature was not written: %s\n", e.what());
        ok = false;
      }
    }
    std::fflush(stdout);
    return ok;
  };
  if (args.wait_for_device) {
    std::printf("waiting      for a device host (hapsim device --session %s)\n",
                args.dds.session.c_str());
    std::fflush(stdout);
    if (!remote.wait_for_host(kUntilStopped_s, &stop)) {
      std::printf("stopped      before a device host joined\n");
      SessionSummary nothing;
      if (recorder) {
        finish_session_recording(*recorder, nothing);
      }
      const bool recorded = report_recording(nothing);
      json_out.write_failure("stopped by " + std::string(stop_signal_name()) +
                             " before a device host joined");
      exit_status() = recorded ? stopped_by_signal_status() : 2;
      return;
    }
  }

  SessionOptions options;
  // Recorded: exactly the scene's step (checked above to be 1 / --rate), as a replay takes it.
  options.dt_s = recorder ? setup.scene.run.dt_s : 1.0 / args.rate_hz;
  options.duration_s = std::isnan(args.duration_s) ? kUntilStopped_s : args.duration_s;
  options.realtime = true;
  options.observer = &publisher;
  options.on_snapshots = [&monitor](TripleBuffer<WorldSnapshot>* s) { monitor.set_snapshots(s); };
  options.on_client = [&monitor](WorldHapticClient* c) { monitor.set_client(c); };
  options.stop = &stop;
  options.recorder = recorder.get();
  monitor.start();
  SessionSummary summary;
  try {
    summary = run_session(world, remote, options);
  } catch (...) {
    monitor.stop();
    throw;
  }
  monitor.stop();

  if (recorder) {
    finish_session_recording(*recorder, summary);  // before the summary, which says a failure
  }
  std::cout << format_session_summary(summary);
  const bool recorded = report_recording(summary);
  const net::VerdictCounts verdicts = remote.verdicts();
  std::printf("published    %" PRIu64 " local models (%" PRIu64 " refused by DDS), %" PRIu64
              " view states\n",
              publisher.published(), publisher.refused_writes(), monitor.views_published());
  for (std::size_t k = 0; k < host_count; ++k) {
    const net::RemoteDevice& host_link = *hosts[k].link;
    const net::VerdictCounts host_verdicts = host_link.verdicts();
    std::printf("%-12s drove %" PRIu64 " of %zu cycles", host_label(hosts[k]).c_str(),
                host_link.cycles_driven(), summary.steps);
    if (k == 0) {
      std::printf(" (lockstep: waited in %" PRIu64 ", %" PRIu64 " ran out)",
                  host_link.lockstep_waits(), host_link.lockstep_timeouts());
    }
    std::printf("; peak force it rendered %.3f N; states:", publisher.peak_rendered_force_n(k));
    for (std::size_t v = 0; v < net::kSampleVerdicts; ++v) {
      std::printf(" %s %" PRIu64 "%s", net::verdict_name(static_cast<net::SampleVerdict>(v)),
                  host_verdicts[v], v + 1 < net::kSampleVerdicts ? "," : "\n");
    }
  }
  const net::VerdictCounts& commands = monitor.command_verdicts();
  const std::uint64_t commands_received = std::accumulate(commands.begin(), commands.end(), 0ULL);
  if (commands_received > 0) {
    std::printf("commands     %" PRIu64 " received:", commands_received);
    for (std::size_t v = 0; v < net::kSampleVerdicts; ++v) {
      std::printf(" %s %" PRIu64 "%s", net::verdict_name(static_cast<net::SampleVerdict>(v)),
                  commands[v], v + 1 < net::kSampleVerdicts ? "," : "");
    }
    std::printf("; material changes the world refused: %" PRIu64 "\n",
                monitor.refused_material_changes());
  }
  if (!args.link_shim.empty()) {
    std::printf("link shim    lost %" PRIu64 " device states\n", remote.link_lost());
  }
  if (legacy) {
    std::printf("legacy       %" PRIu64 " force packets sent, %" PRIu64
                " not taken by the kernel, %" PRIu64 " finger values clamped to the range\n",
                legacy->counts().sent, legacy->counts().send_failed,
                legacy->counts().clamped_fingers);
  }
  if (json_out) {
    nlohmann::json j =
        session_summary_json(setup.scene, world, summary, "device host or " + setup.device_name);
    j["serve"] = {{"session", args.dds.session},
                  {"domain", args.dds.domain},
                  {"secure", domain.secure()},
                  {"scene_hash", hash},
                  {"models_published", publisher.published()},
                  {"views_published", monitor.views_published()},
                  {"device_host_cycles", remote.cycles_driven()},
                  {"lockstep_waits", remote.lockstep_waits()},
                  {"lockstep_timeouts", remote.lockstep_timeouts()},
                  {"peak_rendered_force_n", publisher.peak_rendered_force_n()}};
    for (std::size_t v = 0; v < net::kSampleVerdicts; ++v) {
      const char* verdict = net::verdict_name(static_cast<net::SampleVerdict>(v));
      j["serve"]["device_states"][verdict] = verdicts[v];
      j["serve"]["commands"][verdict] = commands[v];
    }
    j["serve"]["refused_material_changes"] = monitor.refused_material_changes();
    if (!host_names.empty()) {
      // Several users: each host's share, its tools' forces are under "tools" by name.
      nlohmann::json per_host = nlohmann::json::array();
      for (std::size_t k = 0; k < host_count; ++k) {
        const net::RemoteDevice& host_link = *hosts[k].link;
        nlohmann::json h = {{"name", hosts[k].name},
                            {"device_id", hosts[k].device_id},
                            {"cycles_driven", host_link.cycles_driven()},
                            {"peak_rendered_force_n", publisher.peak_rendered_force_n(k)},
                            {"second_host_states_refused", host_link.other_host_states()}};
        h["tools"] = nlohmann::json::array();
        for (const std::size_t t : host_tools[k]) {
          h["tools"].push_back(world.description().tools[t].name);
        }
        const net::VerdictCounts host_verdicts = host_link.verdicts();
        for (std::size_t v = 0; v < net::kSampleVerdicts; ++v) {
          h["device_states"][net::verdict_name(static_cast<net::SampleVerdict>(v))] =
              host_verdicts[v];
        }
        per_host.push_back(h);
      }
      j["serve"]["device_hosts"] = per_host;
    }
    if (recorder) {
      j["serve"]["recording"] = args.record_path;
      j["serve"]["recording_frames"] = recorder->frames_written();
      if (signer) {
        j["serve"]["recording_signature"] =
            net::recording_signature_path(args.record_path).string();
      }
    }
    j["ok"] = summary.pop_throughs == 0 && summary.max_force_limit_violations == 0 && recorded;
    if (*stop_signal_name() != '\0') {
      j["stopped_by"] = stop_signal_name();
    }
    json_out.write(j);
  }
  if (!recorded) {
    exit_status() = 2;  // an output was not written, as `hapsim run --record` says it
  }
  exit_status() = with_signal_status(exit_status());
}

void serve(const ServeArgs& args) {
  JsonOutput json_out(args.json_path);
  with_failure_json(json_out, [&] { serve(args, json_out); });
}

}  // namespace

void add_serve_command(CLI::App& app) {
  auto args = std::make_shared<ServeArgs>();
  CLI::App* cmd = app.add_subcommand(
      "serve",
      "Simulation host: step a scene in real time, serve local contact models to a device host "
      "(hapsim device) and the scene to viewers (hapsim view --connect) over DDS");
  cmd->add_option("scene", args->scene, "Scene file (JSON, see docs/scene-format.md)")->required();
  cmd->add_option("--rate", args->rate_hz, "Steps per second (default 1000)");
  cmd->add_option("--duration", args->duration_s,
                  "Seconds to serve (default: until stopped; counted from the device host's "
                  "first state with --wait-for-device)")
      ->check(positive_seconds());
  cmd->add_flag("--wait-for-device", args->wait_for_device,
                "Step nothing until a device host's first state arrives (a served run then "
                "covers exactly what the device did)");
  cmd->add_option("--device-id", args->device_id, "Device id the models are for (default 0)")
      ->check(CLI::Range(0, 65535));
  cmd->add_option("--view-rate", args->view_rate_hz,
                  "View states per second for viewers (default 30)");
  cmd->add_option("--data", args->data_dir, "The scene's data folder");
  cmd->add_option("--lockstep-us", args->lockstep_us,
                  "While a device host drives, wait up to this long in a cycle for its next "
                  "state and step at once (the model then reaches the device before its next "
                  "cycle); 0: step on the deadline only (default 800)")
      ->check(CLI::Range(0.0, 5000.0));
  cmd->add_option("--link-shim", args->link_shim,
                  "Pass the device states received through a simulated link: "
                  "delay_ms=D,jitter_ms=J,loss=L,outage_at_s=T,outage_s=S,seed=N (no root, no "
                  "netem)");
  cmd->add_option("--legacy-force-udp", args->legacy_force_udp,
                  "Also send the knee paper's force packet (4 fingers, 32-bit, network order) to "
                  "HOST:PORT every cycle, for an old force host");
  cmd->add_option("--json", args->json_path,
                  "Write the summary as JSON (the keys of hapsim run --json, plus 'serve')");
  cmd->add_option("--record", args->record_path,
                  "Record every stepped cycle to FILE (as hapsim run --record; replays with "
                  "hapsim run --replay, scored by hapsim assess); with --secure also FILE.sig, "
                  "signed by this serve's identity (hapsim assess --verify)");
  add_dds_options(cmd, args->dds, net::SecurityRole::kServe);
  cmd->add_flag("--insecure", args->insecure,
                "Serve plain DDS on a network interface other than lo (refused without it: use "
                "--secure DIR)");
  cmd->callback([args] {
    (void)net::session_partition(args->dds.session);  // a bad name is one line before anything runs
    // Plain DDS off this machine only when said (an interface's bad name is the domain's line).
    const std::string& itf = args->dds.interface;
    const bool named = std::all_of(itf.begin(), itf.end(), [](char c) {
      return std::isalnum(static_cast<unsigned char>(c)) != 0 || c == '.' || c == ':' || c == '-' ||
             c == '_';
    });
    if (!args->dds.secure() && !itf.empty() && named && itf != "lo" && !args->insecure) {
      throw CommandError("--interface " + itf +
                         ": serving plain DDS off this machine needs --insecure (or --secure DIR: "
                         "docs/security.md)");
    }
    if (args->dds.secure() && args->insecure) {
      throw CommandError("--insecure: --secure " + args->dds.secure_dir +
                         " is given too (choose one; HAPSIM_SECURE_DIR counts as --secure)");
    }
    serve(*args);
  });
}

}  // namespace hapsim::app
