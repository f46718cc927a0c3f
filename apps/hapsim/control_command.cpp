// `hapsim control ACTION`: an operator's commands to a served world (docs/architecture.md
// #distribution): pause it, resume it, reset it to the scene's start, or give a material new
// contact values — what a connected viewer's buttons do, from a script or another terminal. It
// finds the session's simulation host (its SceneInfo), sends the command (net/command_sender.h)
// and waits until the host shows it took effect: a view state paused or running again, the
// world's time back at the start; a material change until the host acknowledged it (serve
// prints what it set, and what the world refused).
#include "commands.h"
#include "dds_options.h"
#include "session_join.h"
#include "stop_signal.h"

#include "hapsim/net/command_reply.h"
#include "hapsim/net/command_sender.h"
#include "hapsim/net/dds_domain.h"
#include "hapsim/net/loaned_reader.h"
#include "hapsim/net/participant.h"
#include "hapsim/net/served_scene.h"
#include "hapsim/net/topic_reader.h"
#include "hapsim/scene/run_setup.h"
#include "hapsim/world/world.h"

#include <chrono>
#include <cinttypes>
#include <cmath>
#include <cstdio>
#include <memory>
#include <optional>
#include <string>
#include <thread>
#include <vector>

namespace hapsim::app {
namespace {

struct ControlArgs {
  std::string action;
  std::string material;
  DdsOptions dds;
  double timeout_s = 5.0;
  std::optional<double> stiffness_n_per_m;
  std::optional<double> max_force_n;
  std::optional<double> max_depth_mm;
  std::optional<double> damping_n_s_per_m;
  std::optional<double> static_friction;
  std::optional<double> dynamic_friction;
};

// The index of the material named `name` (or given by its index) in the served world: the scene
// built here as the host built it (its materials in the world's order, teleop rigs' included).
std::uint32_t material_index(const net::SceneInfoSample& info, const std::string& name) {
  const RunSetup setup = net::build_served_scene(info, DeviceChoice::external());
  const std::vector<MaterialDescription>& materials = setup.world->description().materials;
  std::string known;
  for (std::size_t i = 0; i < materials.size(); ++i) {
    if (materials[i].name == name || std::to_string(i) == name) {
      return static_cast<std::uint32_t>(i);
    }
    known += (known.empty() ? "" : ", ") + materials[i].name;
  }
  throw CommandError("material '" + name + "': " + info.scene_file + " has no such material" +
                     (known.empty() ? std::string() : " (it has " + known + ")"));
}

net::SessionCommand make_command(const ControlArgs& args, const net::SceneInfoSample& info) {
  namespace f = net::material_field;
  net::SessionCommand c;
  c.kind = net::command_kind(args.action).value();  // checked before connecting
  const bool any_value = args.stiffness_n_per_m || args.max_force_n || args.max_depth_mm ||
                         args.damping_n_s_per_m || args.static_friction || args.dynamic_friction;
  if (c.kind != net::SessionCommandKind::kSetMaterial) {
    if (!args.material.empty() || any_value) {
      throw CommandError("control " + args.action + ": takes no material or values");
    }
    return c;
  }
  if (args.material.empty() || !any_value) {
    throw CommandError(
        "control material: name a material and at least one of --stiffness, --max-force, "
        "--max-depth-mm, --damping, --static-friction, --dynamic-friction");
  }
  c.material = material_index(info, args.material);
  const auto set = [&c](const std::optional<double>& value, std::uint16_t field, double& out,
                        double scale) {
    if (value) {
      c.material_fields |= field;
      out = *value * scale;
    }
  };
  set(args.stiffness_n_per_m, f::kStiffness, c.contact.stiffness_n_per_m, 1.0);
  set(args.max_force_n, f::kMaxForce, c.contact.max_force_n, 1.0);
  set(args.max_depth_mm, f::kMaxPenetration, c.contact.max_penetration_m, 1e-3);
  set(args.damping_n_s_per_m, f::kDamping, c.contact.damping_n_s_per_m, 1.0);
  set(args.static_friction, f::kStaticFriction, c.contact.static_friction, 1.0);
  set(args.dynamic_friction, f::kDynamicFriction, c.contact.dynamic_friction, 1.0);
  return c;
}

// The newest view state from `serve_id`: its time and whether the host is paused.
struct HostView {
  double sim_time_s = 0.0;
  bool paused = false;
};

std::optional<HostView> take_newest_view(net::LoanedReader<hapsim_msg_ViewState>& views,
                                         std::uint64_t serve_id) {
  std::optional<HostView> newest;
  views.take([&](const hapsim_msg_ViewState& m) {
    if (m.serve_id == serve_id && std::isfinite(m.sim_time_s)) {
      newest = HostView{m.sim_time_s, m.paused};
    }
  });
  return newest;
}

// The host's reply to the command `sender` sent last, until `deadline` (or a stop signal).
std::optional<net::CommandReplySample> wait_for_reply(
    net::TopicReader<hapsim_msg_CommandReply>& replies, const net::CommandSender& sender,
    std::uint64_t serve_id, std::chrono::steady_clock::time_point deadline,
    const std::atomic<bool>& stop) {
  std::optional<net::CommandReplySample> found;
  while (!found && std::chrono::steady_clock::now() < deadline &&
         !stop.load(std::memory_order_relaxed)) {
    replies.take([&](const hapsim_msg_CommandReply& m, const dds_sample_info_t& /*info*/) {
      if (m.issuer_id == sender.issuer_id() && m.command_sequence == sender.sequence() &&
          m.serve_id == serve_id) {
        found = net::decode_command_reply(m);
      }
    });
    if (!found) {
      std::this_thread::sleep_for(std::chrono::milliseconds(5));
    }
  }
  return found;
}

void control(const ControlArgs& args) {
  using Clock = std::chrono::steady_clock;
  if (!net::command_kind(args.action)) {
    throw CommandError("control " + args.action + ": expected pause, resume, reset or material");
  }
  if (!(args.timeout_s > 0.0 && args.timeout_s <= 3600.0)) {
    throw CommandError("--timeout " + std::to_string(args.timeout_s) +
                       ": expected more than 0 and at most 3600 s");
  }
  SessionJoin session(args.dds, args.timeout_s);
  const net::SceneInfoSample* info = &session.info();
  net::LoanedReader<hapsim_msg_ViewState>& views_in = session.views();
  const std::atomic<bool>& stop = session.stop();
  const net::SessionCommand command = make_command(args, *info);
  net::CommandSender sender(session.participant(), *info);
  net::TopicReader<hapsim_msg_CommandReply> replies(session.participant());
  const auto deadline = Clock::now() + std::chrono::duration_cast<Clock::duration>(
                                           std::chrono::duration<double>(args.timeout_s));
  // The host's reader must be matched, or a reliable write has no one to reach.
  while (sender.matched_hosts() == 0 && Clock::now() < deadline) {
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
  }
  // The host's time before the command (a reset shows as a later view with an earlier time).
  std::optional<HostView> before;
  while (!before && Clock::now() < deadline) {
    before = take_newest_view(views_in, info->serve_id);
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
  }
  if (!before) {
    throw CommandError("the simulation host in session '" + args.dds.session +
                       "' sends no view states: is it stepping (hapsim serve)?");
  }
  if (!sender.send(command)) {
    throw CommandError("could not send the command on DDS");
  }
  const char* name = net::command_name(command.kind);
  // The reply says whether the host took it; the transport's acknowledgement only that it arrived.
  const auto reply_deadline = Clock::now() + std::chrono::duration_cast<Clock::duration>(
                                                 std::chrono::duration<double>(args.timeout_s));
  const std::optional<net::CommandReplySample> reply =
      wait_for_reply(replies, sender, info->serve_id, reply_deadline, stop);
  if (!reply) {
    throw CommandError(std::string("control ") + name + ": the host in session '" +
                       args.dds.session + "' did not answer within " +
                       std::to_string(args.timeout_s) + " s");
  }
  if (!reply->accepted) {
    throw CommandError(std::string("control ") + name + ": the host refused it: " + reply->reason);
  }
  if (command.kind == net::SessionCommandKind::kSetMaterial) {
    std::printf(
        "control      material %s: %s (session '%s') took the new values; serve prints what it "
        "set\n",
        args.material.c_str(), info->scene_file.c_str(), args.dds.session.c_str());
    return;
  }
  while (Clock::now() < deadline && !stop.load(std::memory_order_relaxed)) {
    if (const std::optional<HostView> view = take_newest_view(views_in, info->serve_id)) {
      const bool done = (command.kind == net::SessionCommandKind::kPause && view->paused) ||
                        (command.kind == net::SessionCommandKind::kResume && !view->paused) ||
                        (command.kind == net::SessionCommandKind::kReset &&
                         view->sim_time_s < before->sim_time_s);
      if (done) {
        std::printf("control      %s: %s (session '%s') %s at t = %.3f s\n", name,
                    info->scene_file.c_str(), args.dds.session.c_str(),
                    view->paused ? "is paused" : "is running", view->sim_time_s);
        return;
      }
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
  }
  throw CommandError(std::string("control ") + name + ": the host in session '" + args.dds.session +
                     "' did not show it within " + std::to_string(args.timeout_s) + " s");
}

}  // namespace

void add_control_command(CLI::App& app) {
  auto args = std::make_shared<ControlArgs>();
  CLI::App* cmd = app.add_subcommand(
      "control",
      "Pause, resume or reset a served world, or change a material's contact values (what a "
      "connected viewer's buttons do), and wait until the simulation host shows it");
  cmd->add_option("action", args->action, "pause, resume, reset or material")->required();
  cmd->add_option("material", args->material,
                  "For 'material': the material's name in the scene (or its index)");
  cmd->add_option("--stiffness", args->stiffness_n_per_m, "Contact stiffness, N/m");
  cmd->add_option("--max-force", args->max_force_n, "Force cap, N");
  cmd->add_option("--max-depth-mm", args->max_depth_mm,
                  "Penetration at which the spring stops "
                  "growing, mm");
  cmd->add_option("--damping", args->damping_n_s_per_m, "Contact damping, N s/m");
  cmd->add_option("--static-friction", args->static_friction, "Static friction coefficient");
  cmd->add_option("--dynamic-friction", args->dynamic_friction, "Dynamic friction coefficient");
  cmd->add_option("--timeout", args->timeout_s,
                  "Seconds to wait for the host and for the command to show (default 5)");
  add_dds_options(cmd, args->dds, net::SecurityRole::kInstructor);
  cmd->callback([args] {
    (void)net::session_partition(args->dds.session);  // a bad name is one line before anything runs
    control(*args);
  });
}

}  // namespace hapsim::app
