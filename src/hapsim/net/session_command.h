// What a viewer or an operator asks of a simulation host over DDS (net/idl Command): pause the
// world, resume it, reset it to the scene's start, or give one material new contact values. The
// issuer encodes (`hapsim command`, a connected viewer's buttons); the host's CommandGate gives
// every received command one verdict, counts it, and only an accepted one is acted on — never
// on the haptic thread (the host hands it to WorldHapticClient, whose haptic thread applies it).
#pragma once

#include "hapsim/force/contact_material.h"
#include "hapsim/net/sample_verdict.h"
#include "hapsim_messages.h"

#include <cstddef>
#include <cstdint>
#include <optional>
#include <string>
#include <string_view>
#include <unordered_map>

namespace hapsim::net {

enum class SessionCommandKind : std::uint16_t {
  kPause = 1,
  kResume = 2,
  kReset = 3,
  kSetMaterial = 4,
};

/// The lower-case name ("pause", "resume", "reset", "material").
[[nodiscard]] const char* command_name(SessionCommandKind kind) noexcept;
/// The kind named `name` (as command_name gives it), or nullopt.
[[nodiscard]] std::optional<SessionCommandKind> command_kind(std::string_view name) noexcept;

/// Which contact values a kSetMaterial command sets (bits of Command::material_fields).
namespace material_field {
inline constexpr std::uint16_t kStiffness = 1u << 0;
inline constexpr std::uint16_t kMaxPenetration = 1u << 1;
inline constexpr std::uint16_t kMaxForce = 1u << 2;
inline constexpr std::uint16_t kDamping = 1u << 3;
inline constexpr std::uint16_t kStaticFriction = 1u << 4;
inline constexpr std::uint16_t kDynamicFriction = 1u << 5;
inline constexpr std::uint16_t kAll = (1u << 6) - 1;
}  // namespace material_field

struct SessionCommand {
  SessionCommandKind kind = SessionCommandKind::kPause;
  /// kSetMaterial: the material's index in the scene, the fields to set and their values.
  std::uint32_t material = 0;
  std::uint16_t material_fields = 0;
  ContactMaterial contact;
};

/// The message for `command` from `issuer_id` (its `sequence`-th) to the start `serve_id` of the
/// host running `scene_hash`.
[[nodiscard]] hapsim_msg_Command encode_session_command(const SessionCommand& command,
                                                        std::uint64_t issuer_id,
                                                        std::uint64_t sequence,
                                                        std::uint64_t scene_hash,
                                                        std::uint64_t serve_id) noexcept;

/// `current` with the fields `command` sets replaced by its values.
[[nodiscard]] ContactMaterial apply_material_fields(const ContactMaterial& current,
                                                    const SessionCommand& command) noexcept;

/// The most a command may ask for: beyond these it is refused as out of range (the world then
/// refuses, on its own, values a step cannot use or a sheet would not settle with).
struct CommandLimits {
  double max_stiffness_n_per_m = 1e6;
  double max_penetration_m = 1.0;
  double max_force_n = 1e3;
  double max_damping_n_s_per_m = 1e4;
  double max_friction = 10.0;
  /// Issuers remembered for ordering (a flood of made-up issuers must not grow the host's
  /// memory). A new one beyond this takes the place of the one heard from least recently: a
  /// flood cannot lock out a live issuer's Pause or Reset (it is heard again as a new issuer),
  /// at the price of forgetting the order of the one evicted.
  std::size_t max_issuers = 1024;
};

class CommandGate {
 public:
  /// For the host start `serve_id` running `scene_hash` with `material_count` materials.
  CommandGate(std::uint64_t scene_hash, std::uint64_t serve_id, std::size_t material_count,
              CommandLimits limits = {});

  /// The verdict on `message`, counted: malformed (an unknown kind or field, a non-finite value
  /// set, a material the scene does not have), out of range (a negative or too large value),
  /// other scene, stale (meant for another start of the host), out of order (not newer than the
  /// issuer's newest accepted). On kAccepted `out` holds the command.
  SampleVerdict admit(const hapsim_msg_Command& message, SessionCommand& out);

  /// Why `message` got `verdict`, in words for the issuer ("out of range: stiffness 1e+09 N/m is
  /// beyond 0 .. 1e+06 N/m"); "" for kAccepted. Call before admit() counts a later command.
  [[nodiscard]] std::string explain(const hapsim_msg_Command& message, SampleVerdict verdict) const;

  [[nodiscard]] const VerdictCounts& counts() const noexcept { return counts_; }
  /// Issuers forgotten to make room for a new one (limits.max_issuers).
  [[nodiscard]] std::uint64_t evicted_issuers() const noexcept { return evicted_issuers_; }
  [[nodiscard]] std::uint64_t count(SampleVerdict verdict) const noexcept {
    return counts_[static_cast<std::size_t>(verdict)];
  }

 private:
  [[nodiscard]] SampleVerdict check(const hapsim_msg_Command& m) const noexcept;

  std::uint64_t scene_hash_;
  std::uint64_t serve_id_;
  std::size_t material_count_;
  CommandLimits limits_;
  struct IssuerOrder {
    std::uint64_t newest_sequence = 0;
    std::uint64_t last_heard = 0;  ///< admit() calls so far when it was last accepted
  };
  std::unordered_map<std::uint64_t, IssuerOrder> newest_per_issuer_;
  std::uint64_t admitted_ = 0;
  std::uint64_t evicted_issuers_ = 0;
  VerdictCounts counts_{};
};

}  // namespace hapsim::net
