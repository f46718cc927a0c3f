#include "hapsim/net/command_receiver.h"

#include "hapsim/net/command_reply.h"
#include "hapsim/world/world.h"

#include <cinttypes>
#include <cstdio>

namespace hapsim::net {

CommandReceiver::CommandReceiver(const Participant& participant, const World& world,
                                 std::uint64_t scene_hash, std::uint64_t serve_id)
    : reader_(participant),
      replies_(participant),
      serve_id_(serve_id),
      gate_(scene_hash, serve_id, world.description().materials.size()) {
  for (const MaterialDescription& m : world.description().materials) {
    materials_.push_back(m.contact);
  }
}

CommandEvent CommandReceiver::receive(const hapsim_msg_Command& m, WorldHapticClient& client) {
  CommandEvent event = act(m, client);
  CommandReplySample reply;
  reply.issuer_id = m.issuer_id;
  reply.command_sequence = m.command_sequence;
  reply.serve_id = serve_id_;
  reply.accepted = event.verdict == SampleVerdict::kAccepted && event.applied;
  reply.reason = event.reason;
  (void)replies_.write(encode_command_reply(reply));  // a lost reply: the issuer times out
  return event;
}

CommandEvent CommandReceiver::act(const hapsim_msg_Command& m, WorldHapticClient& client) {
  CommandEvent event;
  event.issuer_id = m.issuer_id;
  event.verdict = gate_.admit(m, event.command);
  if (event.verdict != SampleVerdict::kAccepted) {
    event.reason = gate_.explain(m, event.verdict);
    return event;
  }
  switch (event.command.kind) {
    case SessionCommandKind::kPause:
    case SessionCommandKind::kResume:
      client.set_paused(event.command.kind == SessionCommandKind::kPause);
      event.applied = true;
      break;
    case SessionCommandKind::kReset:
      client.request_reset();
      event.applied = true;
      break;
    case SessionCommandKind::kSetMaterial: {
      ContactMaterial& current = materials_.at(event.command.material);
      event.material = apply_material_fields(current, event.command);
      event.applied = client.request_material(event.command.material, event.material);
      if (event.applied) {
        current = event.material;
      } else {
        ++not_applied_;
        event.reason = "not applied: too many changes at once";
      }
      break;
    }
  }
  return event;
}

std::string describe_command_event(const CommandEvent& event,
                                   const std::vector<std::string>& material_names) {
  char issuer[32];
  std::snprintf(issuer, sizeof issuer, "%08" PRIx64, event.issuer_id >> 32U);
  std::string line = std::string(command_name(event.command.kind)) + " from " + issuer;
  if (event.verdict != SampleVerdict::kAccepted) {
    return "refused a command from " + std::string(issuer) + ": " + event.reason;
  }
  if (event.command.kind == SessionCommandKind::kSetMaterial) {
    const ContactMaterial& c = event.material;
    const std::string name = event.command.material < material_names.size()
                                 ? material_names[event.command.material]
                                 : std::to_string(event.command.material);
    char values[256];
    std::snprintf(values, sizeof values,
                  ": %s to k %.0f N/m, max force %.2f N, max depth %.1f mm, damping %.2f N s/m, "
                  "friction %.2f/%.2f",
                  name.c_str(), c.stiffness_n_per_m, c.max_force_n, c.max_penetration_m * 1e3,
                  c.damping_n_s_per_m, c.static_friction, c.dynamic_friction);
    line += values;
  }
  if (!event.applied) {
    line += " (not applied: too many changes at once)";
  }
  return line;
}

}  // namespace hapsim::net
