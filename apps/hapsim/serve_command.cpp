// `hapsim serve SCENE`: the simulation host of issue 12. Steps the scene's world at --rate on
// absolute deadlines and publishes, per tool, the local contact model the device renders from
// (world/local_model_builder.h) on the session's DDS partition. A device host's state
// (`hapsim device`, or anything that writes the DeviceState topic) drives the world while it
// keeps arriving; without one, or 100 ms after the last, the scene's own script does. Every
// received state goes through the gate (net/device_state_gate.h): rejections are counted by
// reason and printed at the end. Runs until --duration or SIGINT/SIGTERM.
//
// Not yet (issue 12): the tissue driven by the force the device rendered, scene state for
// viewers, the rendered-force log, --legacy-force-udp.
#include "commands.h"

#include "hapsim/core/device_profile.h"
#include "hapsim/device/force_safety.h"
#include "hapsim/net/dds_domain.h"
#include "hapsim/net/device_state_gate.h"
#include "hapsim/net/local_model_codec.h"
#include "hapsim/net/participant.h"
#include "hapsim/net/scene_hash.h"
#include "hapsim/net/topic_reader.h"
#include "hapsim/net/topic_writer.h"
#include "hapsim/runtime/deadline_clock.h"
#include "hapsim/runtime/latency_histogram.h"
#include "hapsim/scene/run_setup.h"
#include "hapsim/scene/scene_file.h"
#include "hapsim/world/local_model_builder.h"

#include <atomic>
#include <cinttypes>
#include <cmath>
#include <csignal>
#include <cstdio>
#include <limits>
#include <memory>
#include <string>
#include <vector>

namespace hapsim::app {
namespace {

struct ServeArgs {
  std::string scene;
  double rate_hz = 1000.0;
  double duration_s = std::numeric_limits<double>::quiet_NaN();  // NaN: until stopped
  std::string session = "default";
  int domain = 0;
  int device_id = 0;
  std::string data_dir;
};

volatile std::sig_atomic_t g_stop = 0;
extern "C" void request_stop(int /*signal*/) {
  g_stop = 1;
}

// A device host drives the world while its states keep coming; after this long without one the
// scene's script takes over again.
constexpr std::int64_t kDeviceHostTimeout_ns = 100'000'000;

void serve(const ServeArgs& args) {
  if (!(args.rate_hz >= 10.0 && args.rate_hz <= 10'000.0)) {
    throw CommandError("--rate " + std::to_string(args.rate_hz) + ": expected 10 to 10000 Hz");
  }
  SceneLoadOptions load_options;
  if (!args.data_dir.empty()) {
    load_options.data_dir = args.data_dir;
  }
  RunSetup setup =
      make_run_setup(load_scene(args.scene, load_options), DeviceChoice::scene_script());
  World& world = *setup.world;
  if (world.rig() != nullptr) {
    throw CommandError(args.scene + ": a teleoperation rig is not served over the network yet");
  }
  const std::uint64_t hash = net::scene_hash(world.content_hash());
  const auto device_id = static_cast<std::uint16_t>(args.device_id);
  const std::size_t tools = std::min<std::size_t>(world.description().tools.size(), kMaxFingers);

  net::DdsDomain domain(args.domain, HAPSIM_DEFAULT_DDS_CONFIG);
  net::Participant participant(args.domain, args.session);
  net::TopicWriter<hapsim_msg_LocalModel> models_out(participant);
  net::TopicReader<hapsim_msg_DeviceState> states_in(participant);
  net::DeviceStateGate gate(device_id, hash);
  const LocalModelBuilder builder(world.model());
  std::vector<LocalContactModel> models(tools);

  std::printf("serve        %s, %zu tool(s), scene hash %016" PRIx64 "\n", args.scene.c_str(),
              tools, hash);
  std::printf("dds          domain %d, session '%s' (partition %s), config %s\n", args.domain,
              args.session.c_str(), participant.partition().c_str(), domain.config().c_str());
  std::fflush(stdout);

  std::signal(SIGINT, request_stop);
  std::signal(SIGTERM, request_stop);
  const double dt_s = 1.0 / args.rate_hz;
  const auto period_ns = static_cast<std::int64_t>(std::llround(1e9 / args.rate_hz));
  const std::int64_t steps_max =
      std::isnan(args.duration_s)
          ? std::numeric_limits<std::int64_t>::max()
          : static_cast<std::int64_t>(std::llround(args.duration_s * args.rate_hz));
  DeadlineClock clock(period_ns, 0);
  LatencyHistogram step_cost;
  net::DeviceStateSample host_state;
  std::int64_t host_seen_ns = std::numeric_limits<std::int64_t>::min() / 2;
  bool host_driving = false;
  std::uint64_t host_cycles = 0;
  std::uint64_t published = 0;
  std::uint64_t late_cycles = 0;
  std::int64_t steps = 0;
  clock.start();
  std::int64_t previous_wake_ns = monotonic_ns();
  for (; steps < steps_max && g_stop == 0; ++steps) {
    const std::int64_t wake_ns = clock.wait_next();
    late_cycles += wake_ns - previous_wake_ns > 2 * period_ns ? 1 : 0;
    previous_wake_ns = wake_ns;
    const double t_s = static_cast<double>(steps) * dt_s;
    states_in.take([&](const hapsim_msg_DeviceState& m, const dds_sample_info_t&) {
      if (gate.admit(m, host_state) == net::SampleVerdict::kAccepted) {
        host_seen_ns = wake_ns;
      }
    });
    const bool host_now = wake_ns - host_seen_ns < kDeviceHostTimeout_ns;
    if (host_now != host_driving) {
      // A transition, a few times a run at most: worth a line.
      std::printf(
          "device host  %s at %.3f s\n",
          host_now ? "joined: its states drive the world" : "silent: back to the scene's script",
          t_s);
      std::fflush(stdout);
      host_driving = host_now;
      // The host's device and the script are a long way apart: the tools jump, so no velocity
      // (no ~1000 m/s in the next local model) and no contact side or stick point is kept.
      world.forget_tool_motion();
    }
    DeviceInput input = setup.device->read(t_s);
    if (host_driving) {
      input = host_state.input;
      input.time_s = t_s;
      ++host_cycles;
    }
    const std::int64_t step_start_ns = monotonic_ns();
    const StepResult& result = world.step(input, dt_s);
    setup.device->write(clamp_command(result.command, *setup.profile));
    builder.build(world.state(), static_cast<std::uint64_t>(steps) + 1,
                  host_driving ? host_state.sequence : 0, models);
    for (std::size_t t = 0; t < tools; ++t) {
      published += models_out.write(net::encode_local_model(
                       models[t], {device_id, static_cast<std::uint16_t>(t)}, hash))
                       ? 1
                       : 0;
    }
    step_cost.record_us(static_cast<double>(monotonic_ns() - step_start_ns) * 1e-3);
  }

  const LatencyPercentilesUs cost = step_cost.summary();
  std::printf("served       %" PRId64 " steps (%.3f s simulated) at %.0f Hz, %" PRIu64
              " late cycles; step + models p50 %.1f us, p99 %.1f us\n",
              steps, static_cast<double>(steps) * dt_s, args.rate_hz, late_cycles, cost.p50,
              cost.p99);
  std::printf("published    %" PRIu64 " local models (%" PRIu64 " refused by DDS)\n", published,
              models_out.failed_writes());
  std::printf("device host  drove %" PRIu64 " cycles; states:", host_cycles);
  for (std::size_t v = 0; v < net::kSampleVerdicts; ++v) {
    std::printf(" %s %" PRIu64 "%s", net::verdict_name(static_cast<net::SampleVerdict>(v)),
                gate.counts()[v], v + 1 < net::kSampleVerdicts ? "," : "\n");
  }
}

}  // namespace

void add_serve_command(CLI::App& app) {
  auto args = std::make_shared<ServeArgs>();
  CLI::App* cmd = app.add_subcommand(
      "serve", "Simulation host: step a scene and publish local contact models over DDS");
  cmd->add_option("scene", args->scene, "Scene file (JSON, see docs/scene-format.md)")->required();
  cmd->add_option("--rate", args->rate_hz, "Steps per second (default 1000)");
  cmd->add_option("--duration", args->duration_s, "Seconds to serve (default: until stopped)")
      ->check(CLI::PositiveNumber);
  cmd->add_option("--session", args->session,
                  "Session name: a DDS partition, so sessions never see each other (default "
                  "'default')");
  cmd->add_option("--domain", args->domain, "DDS domain id (default 0)")->check(CLI::Range(0, 232));
  cmd->add_option("--device-id", args->device_id, "Device id the models are for (default 0)")
      ->check(CLI::Range(0, 65535));
  cmd->add_option("--data", args->data_dir, "The scene's data folder");
  cmd->callback([args] {
    (void)net::session_partition(args->session);  // a bad name is one line before anything runs
    serve(*args);
  });
}

}  // namespace hapsim::app
