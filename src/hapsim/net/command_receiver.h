// The simulation host's side of the Command topic (net/session_command.h): takes what viewers and
// operators asked, gates it, and hands what is accepted to the running loop's client — pause and
// resume (WorldHapticClient::set_paused), reset (request_reset), a material's contact values
// (request_material: the haptic thread applies them before its next step, and the world refuses
// values a step cannot use). Off the haptic path: `hapsim serve` polls it from its monitor thread.
#pragma once

#include "hapsim/net/participant.h"
#include "hapsim/net/session_command.h"
#include "hapsim/net/topic_reader.h"
#include "hapsim/net/topic_writer.h"
#include "hapsim/runtime/world_haptic_client.h"

#include <cstdint>
#include <string>
#include <vector>

namespace hapsim::net {

/// What one received command came to.
struct CommandEvent {
  std::uint64_t issuer_id = 0;
  SampleVerdict verdict = SampleVerdict::kAccepted;
  SessionCommand command;
  /// Accepted and handed to the client (false: the client's material queue was full).
  bool applied = false;
  /// The material's values asked for (kSetMaterial), with the fields not set kept.
  ContactMaterial material;
  /// Why it was refused or not applied ("" when applied), as the issuer's reply says it.
  std::string reason;
};

class CommandReceiver {
 public:
  /// For the host start `serve_id` of `world` (its materials' described values are the start).
  CommandReceiver(const Participant& participant, const World& world, std::uint64_t scene_hash,
                  std::uint64_t serve_id);

  /// Takes what arrived (nothing while `client` is null: commands wait in the reader until the
  /// loop runs), acts on each accepted command, answers each issuer (net/command_reply.h:
  /// accepted, or refused and why) and calls on_event(const CommandEvent&) for each.
  template <typename OnEvent>
  void poll(WorldHapticClient* client, OnEvent&& on_event) {
    if (client == nullptr) {
      return;
    }
    reader_.take([&](const hapsim_msg_Command& m, const dds_sample_info_t& /*info*/) {
      on_event(receive(m, *client));
    });
  }

  [[nodiscard]] const VerdictCounts& counts() const noexcept { return gate_.counts(); }
  /// Accepted commands that could not be handed over (the client's material queue was full).
  [[nodiscard]] std::uint64_t not_applied() const noexcept { return not_applied_; }

 private:
  CommandEvent receive(const hapsim_msg_Command& m, WorldHapticClient& client);
  CommandEvent act(const hapsim_msg_Command& m, WorldHapticClient& client);

  TopicReader<hapsim_msg_Command> reader_;
  TopicWriter<hapsim_msg_CommandReply> replies_;
  std::uint64_t serve_id_;
  CommandGate gate_;
  std::vector<ContactMaterial> materials_;  ///< as last asked for, per material
  std::uint64_t not_applied_ = 0;
};

/// One line for `event` (e.g. "pause from 3fa2b1c0 accepted", "material skin: k 800 N/m ...");
/// `material_names`: the scene's, by index.
[[nodiscard]] std::string describe_command_event(const CommandEvent& event,
                                                 const std::vector<std::string>& material_names);

}  // namespace hapsim::net
