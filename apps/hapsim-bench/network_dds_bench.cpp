#include "network_dds_bench.h"

#include "commands.h"
#include "json_output.h"

#include "hapsim/net/dds_domain.h"
#include "hapsim/net/device_state_codec.h"
#include "hapsim/net/participant.h"
#include "hapsim/net/security_config.h"
#include "hapsim/net/security_key_dir.h"
#include "hapsim/net/served_scene.h"
#include "hapsim/net/topic_reader.h"
#include "hapsim/net/topic_writer.h"
#include "hapsim/runtime/latency_histogram.h"

#include <nlohmann/json.hpp>

#include <fcntl.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <atomic>
#include <chrono>
#include <cinttypes>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <string>
#include <thread>
#include <vector>

namespace hapsim::app {
namespace {

// One child process of `hapsim` (beside this hapsim-bench), its output to `log`.
class Child {
 public:
  Child(const std::vector<std::string>& args, const std::filesystem::path& log) {
    // The hapsim in this binary's folder, whatever this one was started as.
    const std::string self =
        (std::filesystem::read_symlink("/proc/self/exe").parent_path() / "hapsim").string();
    std::vector<std::string> words{self};
    words.insert(words.end(), args.begin(), args.end());
    std::vector<char*> argv;
    argv.reserve(words.size() + 1);
    for (std::string& w : words) {
      argv.push_back(w.data());
    }
    argv.push_back(nullptr);
    posix_spawn_file_actions_t actions;
    posix_spawn_file_actions_init(&actions);
    posix_spawn_file_actions_addopen(&actions, 1, log.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
    posix_spawn_file_actions_adddup2(&actions, 1, 2);
    const int rc = posix_spawn(&pid_, self.c_str(), &actions, nullptr, argv.data(), environ);
    posix_spawn_file_actions_destroy(&actions);
    if (rc != 0) {
      throw CommandError("bench network --dds: could not start " + args.front());
    }
  }
  Child(const Child&) = delete;
  Child& operator=(const Child&) = delete;
  Child(Child&& other) noexcept : pid_(other.pid_) { other.pid_ = -1; }
  Child& operator=(Child&&) = delete;
  ~Child() {
    if (pid_ > 0) {
      ::kill(pid_, SIGKILL);
      (void)wait();
    }
  }
  int wait() {
    int status = 0;
    if (pid_ > 0 && ::waitpid(pid_, &status, 0) == pid_) {
      pid_ = -1;
      return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
    }
    return -1;
  }

 private:
  pid_t pid_ = -1;
};

nlohmann::json read_json(const std::filesystem::path& path, const std::filesystem::path& log) {
  std::ifstream in(path);
  if (!in) {
    std::ifstream l(log);
    const std::string output{std::istreambuf_iterator<char>(l), std::istreambuf_iterator<char>()};
    throw CommandError("bench network --dds: no " + path.filename().string() + "; its output:\n" +
                       output);
  }
  return nlohmann::json::parse(in);
}

struct DdsRun {
  int viewers = 0;
  nlohmann::json serve;
  nlohmann::json device;
  std::vector<nlohmann::json> views;
};

DdsRun run_once(const NetworkDdsArgs& args, int viewers, const std::filesystem::path& dir) {
  const std::string session =
      "bench-dds-" + std::to_string(::getpid()) + "-" + std::to_string(viewers);
  const std::vector<std::string> net{"--session", session, "--domain", std::to_string(args.domain)};
  const auto with_net = [&net](std::vector<std::string> a) {
    a.insert(a.end(), net.begin(), net.end());
    return a;
  };
  const auto file = [&dir, viewers](const std::string& name) {
    return dir / (name + "-" + std::to_string(viewers));
  };
  Child serve(with_net({"serve", args.scene, "--wait-for-device", "--duration",
                        std::to_string(args.duration_s), "--json", file("serve.json").string()}),
              file("serve.log"));
  std::vector<Child> watchers;
  for (int v = 0; v < viewers; ++v) {
    const std::string name = "watch" + std::to_string(v);
    watchers.emplace_back(with_net({"watch", "--duration", std::to_string(args.duration_s + 3.0),
                                    "--json", file(name + ".json").string()}),
                          file(name + ".log"));
  }
  // Viewers and serve find each other first; then the device starts the palpation.
  std::this_thread::sleep_for(std::chrono::milliseconds(1500));
  Child device(with_net({"device", "--duration", std::to_string(args.duration_s + 0.5), "--json",
                         file("device.json").string()}),
               file("device.log"));
  const int device_rc = device.wait();
  const int serve_rc = serve.wait();
  DdsRun run;
  run.viewers = viewers;
  if (device_rc != 0 || serve_rc != 0) {
    throw CommandError("bench network --dds: serve exited " + std::to_string(serve_rc) +
                       ", device " + std::to_string(device_rc) + " (logs in " + dir.string() + ")");
  }
  run.device = read_json(file("device.json"), file("device.log"));
  run.serve = read_json(file("serve.json"), file("serve.log"));
  for (int v = 0; v < viewers; ++v) {
    const std::string name = "watch" + std::to_string(v);
    watchers[static_cast<std::size_t>(v)].wait();
    run.views.push_back(read_json(file(name + ".json"), file(name + ".log")));
  }
  return run;
}

// The network's own round trip, without the device loop's wait for its next cycle: this process
// plays the device (the served scene's script at 1 kHz), writes each state and waits on a waitset
// for the model that answers it, timing write to arrival on its own clock. Serve steps in
// lockstep with it (its default), so what is left is transport both ways and one step.
// `secure`: serve and this probe with DDS Security (keys made in dir for the probe's session),
// on domain + 1. `join_ms`: how long a second participant of this process then takes from its
// creation to the served scene (discovery, with --secure the handshake, and the sample).
LatencyPercentilesUs probe_round_trip(const NetworkDdsArgs& args, const std::filesystem::path& dir,
                                      bool secure = false, double* join_ms = nullptr) {
  const std::string session =
      std::string(secure ? "bench-dds-secure-" : "bench-dds-probe-") + std::to_string(::getpid());
  const int domain_id = args.domain + (secure ? 1 : 0);
  const std::filesystem::path keys = dir / ("keys-" + session);
  std::vector<std::string> serve_args{"serve",
                                      args.scene,
                                      "--wait-for-device",
                                      "--duration",
                                      std::to_string(args.duration_s),
                                      "--session",
                                      session,
                                      "--domain",
                                      std::to_string(domain_id)};
  net::DdsNetwork network;
  if (secure) {
    std::filesystem::remove_all(keys);
    (void)net::SecurityKeyDir::init(keys, session, {"device"});
    serve_args.insert(serve_args.end(), {"--secure", keys.string()});
    network.security = net::cyclone_security_xml(keys, "device", session);
    network.security_label = "identity device of " + keys.string();
  }
  const std::filesystem::path log = dir / (secure ? "serve-secure-probe.log" : "serve-probe.log");
  Child serve(serve_args, log);
  net::DdsDomain domain(domain_id, HAPSIM_DEFAULT_DDS_CONFIG, network);
  net::Participant participant(domain_id, session);
  net::LoanedReader<hapsim_msg_SceneInfo> info_in(participant);
  net::TopicReader<hapsim_msg_LocalModel> models(participant);
  net::TopicWriter<hapsim_msg_DeviceState> states(participant);
  const std::optional<net::SceneInfoSample> info = net::wait_for_scene_info(info_in, 30.0);
  if (!info) {
    throw CommandError("bench network --dds: serve did not come up (" + log.string() + ")");
  }
  if (join_ms != nullptr) {
    const auto t0 = std::chrono::steady_clock::now();
    net::Participant again(domain_id, session);
    net::LoanedReader<hapsim_msg_SceneInfo> again_in(again);
    if (!net::wait_for_scene_info(again_in, 30.0)) {
      throw CommandError("bench network --dds: a second participant never saw the scene");
    }
    *join_ms =
        std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
  }
  RunSetup setup = net::build_served_scene(*info, DeviceChoice::scene_script());
  const dds_entity_t waitset = dds_create_waitset(participant.participant());
  dds_set_status_mask(models.handle(), DDS_DATA_AVAILABLE_STATUS);
  dds_waitset_attach(waitset, models.handle(), 0);
  // Written at 1 kHz whatever comes back, as a device does; a second thread stamps each model's
  // arrival by the state it answers (the first one per state).
  const auto steps = static_cast<std::uint64_t>(args.duration_s * 1000.0);
  std::vector<std::chrono::steady_clock::time_point> sent(steps + 1);
  std::vector<std::chrono::steady_clock::time_point> answered(steps + 1);
  std::vector<std::atomic<bool>> done(steps + 1);
  std::atomic<bool> writing{true};
  std::thread receiver([&] {
    while (writing.load(std::memory_order_relaxed)) {
      (void)dds_waitset_wait(waitset, nullptr, 0, DDS_MSECS(5));
      const auto now = std::chrono::steady_clock::now();
      models.take([&](const hapsim_msg_LocalModel& m, const dds_sample_info_t&) {
        const std::uint64_t k = m.device_sequence;
        if (k >= 1 && k <= steps && !done[k].load(std::memory_order_acquire)) {
          answered[k] = now;
          done[k].store(true, std::memory_order_release);
        }
      });
    }
  });
  auto next = std::chrono::steady_clock::now();
  for (std::uint64_t k = 1; k <= steps; ++k) {
    next += std::chrono::milliseconds(1);
    std::this_thread::sleep_until(next);
    net::DeviceStateSample state;
    state.sequence = k;
    state.input = setup.device->read(static_cast<double>(k - 1) * 1e-3);
    sent[k] = std::chrono::steady_clock::now();
    states.write(net::encode_device_state(state, info->scene_hash));
  }
  std::this_thread::sleep_for(std::chrono::milliseconds(20));
  writing.store(false, std::memory_order_relaxed);
  receiver.join();
  LatencyHistogram rtt_us;
  std::uint64_t superseded = 0;
  for (std::uint64_t k = 1; k <= steps; ++k) {
    if (done[k].load(std::memory_order_acquire)) {
      rtt_us.record_us(std::chrono::duration<double, std::micro>(answered[k] - sent[k]).count());
    } else {
      ++superseded;
    }
  }
  const std::uint64_t lost = superseded;
  dds_delete(waitset);
  serve.wait();
  LatencyPercentilesUs p = rtt_us.summary();
  std::printf("[dds] probe: %" PRIu64 " states, %" PRIu64 " unanswered within 5 ms\n", steps, lost);
  return p;
}

nlohmann::json row_of(const DdsRun& r) {
  const nlohmann::json& d = r.device;
  const nlohmann::json& s = r.serve;
  double min_views_per_s = -1.0;
  double sum_views_per_s = 0.0;
  for (const nlohmann::json& v : r.views) {
    const double rate = v["views_per_s"].get<double>();
    min_views_per_s = min_views_per_s < 0.0 ? rate : std::min(min_views_per_s, rate);
    sum_views_per_s += rate;
  }
  return {{"viewers", r.viewers},
          {"round_trip_us", d["round_trip_us"]},
          {"device_rate_hz", d["realtime"]["rate_hz"]},
          {"device_jitter_us", d["realtime"]["period_jitter_us"]},
          {"device_missed_deadlines", d["realtime"]["missed_deadlines"]},
          {"device_scheduling", d["realtime"]["scheduling"]},
          {"device_peak_force_n", d["peak_force_n"]},
          {"serve_rate_hz", s["realtime"]["rate_hz"]},
          {"serve_step_us", s["step_us"]},
          {"serve_missed_deadlines", s["realtime"]["missed_deadlines"]},
          {"serve_peak_force_n", s["tools"][0]["peak_force_n"]},
          {"views_per_s_min", r.views.empty() ? 0.0 : min_views_per_s},
          {"views_per_s_mean",
           r.views.empty() ? 0.0 : sum_views_per_s / static_cast<double>(r.views.size())}};
}

}  // namespace

void run_network_dds(const NetworkDdsArgs& args) {
  if (!std::filesystem::is_regular_file(args.scene)) {
    throw CommandError("--scene " + args.scene + ": no such scene file (run from the checkout)");
  }
  JsonOutput json_out(args.json_path);
  const std::filesystem::path dir =
      std::filesystem::temp_directory_path() / ("hapsim_bench_dds_" + std::to_string(::getpid()));
  std::filesystem::create_directories(dir);
  if (args.secure_compare) {
    nlohmann::json out;
    for (const bool secure : {false, true}) {
      std::printf("[dds] serve + this process as a probe device, %s, %.1f s ...\n",
                  secure ? "DDS Security" : "plain", args.duration_s);
      std::fflush(stdout);
      double join_ms = 0.0;
      const LatencyPercentilesUs p = probe_round_trip(args, dir, secure, &join_ms);
      std::printf(
          "%-8s network round trip p50 %.0f us, p99 %.0f us, max %.0f us over %llu "
          "states; a new participant joined in %.1f ms\n",
          secure ? "secure" : "plain", p.p50, p.p99, p.max,
          static_cast<unsigned long long>(p.count), join_ms);
      out[secure ? "secure" : "plain"] = {
          {"round_trip_us", {{"p50", p.p50}, {"p99", p.p99}, {"max", p.max}, {"count", p.count}}},
          {"join_ms", join_ms}};
    }
    if (json_out) {
      json_out.write(out);
    }
    return;
  }
  nlohmann::json rows = nlohmann::json::array();
  for (const int viewers : {0, args.viewers}) {
    std::printf("[dds] serve + device%s, %.1f s of %s ...\n",
                viewers > 0 ? (" + " + std::to_string(viewers) + " viewers").c_str() : "",
                args.duration_s, args.scene.c_str());
    std::fflush(stdout);
    rows.push_back(row_of(run_once(args, viewers, dir)));
    if (args.viewers == 0) {
      break;
    }
  }
  std::printf("[dds] serve + this process as a probe device, %.1f s ...\n", args.duration_s);
  std::fflush(stdout);
  const LatencyPercentilesUs probe = probe_round_trip(args, dir);
  std::printf("\nover Cyclone DDS on loopback, separate processes (serve, device, viewers)\n");
  std::printf("%-8s %-26s %-34s %-22s %-14s\n", "viewers", "round trip us p50/p99/max",
              "device loop Hz, jitter p99 us, missed", "serve Hz, step p99 us", "views/s min");
  for (const nlohmann::json& r : rows) {
    char rt[64];
    std::snprintf(rt, sizeof rt, "%.0f / %.0f / %.0f", r["round_trip_us"]["p50"].get<double>(),
                  r["round_trip_us"]["p99"].get<double>(), r["round_trip_us"]["max"].get<double>());
    char dev[64];
    std::snprintf(dev, sizeof dev, "%.2f, %.1f, %d (%s)", r["device_rate_hz"].get<double>(),
                  r["device_jitter_us"]["p99"].get<double>(),
                  r["device_missed_deadlines"].get<int>(),
                  r["device_scheduling"].get<std::string>().c_str());
    char srv[64];
    std::snprintf(srv, sizeof srv, "%.2f, %.1f", r["serve_rate_hz"].get<double>(),
                  r["serve_step_us"]["p99"].get<double>());
    std::printf("%-8d %-26s %-34s %-22s %-14.1f\n", r["viewers"].get<int>(), rt, dev, srv,
                r["views_per_s_min"].get<double>());
  }
  std::printf(
      "round trip (device loop): from the device writing a state to its loop taking the first "
      "model that answered it, both ends on the device's clock: one device cycle at least, "
      "since the loop takes models at the start of its next cycle\n");
  std::printf(
      "network round trip (a state written to the model answering it arriving, serve in "
      "lockstep): p50 %.0f us, p99 %.0f us, max %.0f us over %llu states\n",
      probe.p50, probe.p99, probe.max, static_cast<unsigned long long>(probe.count));
  if (json_out) {
    nlohmann::json out;
    out["runs"] = rows;
    out["network_round_trip_us"] = {
        {"p50", probe.p50}, {"p99", probe.p99}, {"max", probe.max}, {"count", probe.count}};
    json_out.write(out);
  }
  std::error_code ec;
  std::filesystem::remove_all(dir, ec);
}

}  // namespace hapsim::app
