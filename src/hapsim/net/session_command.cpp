#include "hapsim/net/session_command.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <utility>

namespace hapsim::net {

namespace {

constexpr std::array<std::pair<SessionCommandKind, const char*>, 4> kNames{{
    {SessionCommandKind::kPause, "pause"},
    {SessionCommandKind::kResume, "resume"},
    {SessionCommandKind::kReset, "reset"},
    {SessionCommandKind::kSetMaterial, "material"},
}};

// A set value: finite (else malformed) and within [0, limit] (else out of range).
enum class ValueCheck { kOk, kNonFinite, kOutOfRange };

ValueCheck check_value(bool set, double value, double limit) noexcept {
  if (!set) {
    return ValueCheck::kOk;
  }
  if (!std::isfinite(value)) {
    return ValueCheck::kNonFinite;
  }
  return value >= 0.0 && value <= limit ? ValueCheck::kOk : ValueCheck::kOutOfRange;
}

}  // namespace

const char* command_name(SessionCommandKind kind) noexcept {
  for (const auto& [k, name] : kNames) {
    if (k == kind) {
      return name;
    }
  }
  return "?";
}

std::optional<SessionCommandKind> command_kind(std::string_view name) noexcept {
  for (const auto& [k, n] : kNames) {
    if (name == n) {
      return k;
    }
  }
  return std::nullopt;
}

hapsim_msg_Command encode_session_command(const SessionCommand& command, std::uint64_t issuer_id,
                                          std::uint64_t sequence, std::uint64_t scene_hash,
                                          std::uint64_t serve_id) noexcept {
  hapsim_msg_Command m{};
  m.issuer_id = issuer_id;
  m.command_sequence = sequence;
  m.scene_hash = scene_hash;
  m.serve_id = serve_id;
  m.kind = static_cast<std::uint16_t>(command.kind);
  if (command.kind == SessionCommandKind::kSetMaterial) {
    m.material = command.material;
    m.material_fields = command.material_fields;
    m.stiffness_n_per_m = command.contact.stiffness_n_per_m;
    m.max_penetration_m = command.contact.max_penetration_m;
    m.max_force_n = command.contact.max_force_n;
    m.damping_n_s_per_m = command.contact.damping_n_s_per_m;
    m.static_friction = command.contact.static_friction;
    m.dynamic_friction = command.contact.dynamic_friction;
  }
  return m;
}

ContactMaterial apply_material_fields(const ContactMaterial& current,
                                      const SessionCommand& command) noexcept {
  namespace f = material_field;
  ContactMaterial c = current;
  const ContactMaterial& v = command.contact;
  const std::uint16_t set = command.material_fields;
  c.stiffness_n_per_m = (set & f::kStiffness) != 0 ? v.stiffness_n_per_m : c.stiffness_n_per_m;
  c.max_penetration_m = (set & f::kMaxPenetration) != 0 ? v.max_penetration_m : c.max_penetration_m;
  c.max_force_n = (set & f::kMaxForce) != 0 ? v.max_force_n : c.max_force_n;
  c.damping_n_s_per_m = (set & f::kDamping) != 0 ? v.damping_n_s_per_m : c.damping_n_s_per_m;
  c.static_friction = (set & f::kStaticFriction) != 0 ? v.static_friction : c.static_friction;
  c.dynamic_friction = (set & f::kDynamicFriction) != 0 ? v.dynamic_friction : c.dynamic_friction;
  return c;
}

CommandGate::CommandGate(std::uint64_t scene_hash, std::uint64_t serve_id,
                         std::size_t material_count, CommandLimits limits)
    : scene_hash_(scene_hash),
      serve_id_(serve_id),
      material_count_(material_count),
      limits_(limits) {}

SampleVerdict CommandGate::check(const hapsim_msg_Command& m) const noexcept {
  const std::optional<SessionCommandKind> kind =
      command_kind(command_name(static_cast<SessionCommandKind>(m.kind)));
  if (!kind) {
    return SampleVerdict::kMalformed;
  }
  if (*kind == SessionCommandKind::kSetMaterial) {
    namespace f = material_field;
    const std::uint16_t set = m.material_fields;
    if (set == 0 || (set & ~f::kAll) != 0 || m.material >= material_count_) {
      return SampleVerdict::kMalformed;
    }
    const std::array<ValueCheck, 6> checks{
        check_value((set & f::kStiffness) != 0, m.stiffness_n_per_m, limits_.max_stiffness_n_per_m),
        check_value((set & f::kMaxPenetration) != 0, m.max_penetration_m,
                    limits_.max_penetration_m),
        check_value((set & f::kMaxForce) != 0, m.max_force_n, limits_.max_force_n),
        check_value((set & f::kDamping) != 0, m.damping_n_s_per_m, limits_.max_damping_n_s_per_m),
        check_value((set & f::kStaticFriction) != 0, m.static_friction, limits_.max_friction),
        check_value((set & f::kDynamicFriction) != 0, m.dynamic_friction, limits_.max_friction),
    };
    for (const ValueCheck c : checks) {
      if (c == ValueCheck::kNonFinite) {
        return SampleVerdict::kMalformed;
      }
    }
    for (const ValueCheck c : checks) {
      if (c == ValueCheck::kOutOfRange) {
        return SampleVerdict::kOutOfRange;
      }
    }
  }
  if (m.scene_hash != scene_hash_) {
    return SampleVerdict::kOtherScene;
  }
  if (m.serve_id != serve_id_) {
    return SampleVerdict::kStale;
  }
  const auto newest = newest_per_issuer_.find(m.issuer_id);
  if (newest == newest_per_issuer_.end()) {
    return SampleVerdict::kAccepted;  // a new issuer (admit makes room for it)
  }
  return m.command_sequence > newest->second.newest_sequence ? SampleVerdict::kAccepted
                                                             : SampleVerdict::kOutOfOrder;
}

SampleVerdict CommandGate::admit(const hapsim_msg_Command& message, SessionCommand& out) {
  const SampleVerdict verdict = check(message);
  ++counts_[static_cast<std::size_t>(verdict)];
  if (verdict != SampleVerdict::kAccepted) {
    return verdict;
  }
  ++admitted_;
  if (!newest_per_issuer_.contains(message.issuer_id) &&
      newest_per_issuer_.size() >= std::max<std::size_t>(1, limits_.max_issuers)) {
    // Full: the issuer heard from least recently makes room (a scan of at most max_issuers, off
    // the haptic path: commands come from people).
    const auto oldest = std::min_element(
        newest_per_issuer_.begin(), newest_per_issuer_.end(),
        [](const auto& a, const auto& b) { return a.second.last_heard < b.second.last_heard; });
    newest_per_issuer_.erase(oldest);
    ++evicted_issuers_;
  }
  newest_per_issuer_[message.issuer_id] = {message.command_sequence, admitted_};
  out = SessionCommand{};
  out.kind = static_cast<SessionCommandKind>(message.kind);
  if (out.kind == SessionCommandKind::kSetMaterial) {
    out.material = message.material;
    out.material_fields = message.material_fields;
    out.contact.stiffness_n_per_m = message.stiffness_n_per_m;
    out.contact.max_penetration_m = message.max_penetration_m;
    out.contact.max_force_n = message.max_force_n;
    out.contact.damping_n_s_per_m = message.damping_n_s_per_m;
    out.contact.static_friction = message.static_friction;
    out.contact.dynamic_friction = message.dynamic_friction;
  }
  return verdict;
}

std::string CommandGate::explain(const hapsim_msg_Command& m, SampleVerdict verdict) const {
  const std::string name = verdict_name(verdict);
  if (verdict == SampleVerdict::kAccepted) {
    return "";
  }
  const auto kind = static_cast<SessionCommandKind>(m.kind);
  if (!command_kind(command_name(kind))) {
    return name + ": unknown command kind " + std::to_string(m.kind);
  }
  if (kind == SessionCommandKind::kSetMaterial &&
      (verdict == SampleVerdict::kMalformed || verdict == SampleVerdict::kOutOfRange)) {
    namespace f = material_field;
    if (m.material >= material_count_) {
      return name + ": material " + std::to_string(m.material) + " (the scene has " +
             std::to_string(material_count_) + ")";
    }
    if (m.material_fields == 0 || (m.material_fields & ~f::kAll) != 0) {
      return name + ": no known contact value set";
    }
    struct Field {
      std::uint16_t bit;
      const char* what;
      double value;
      double limit;
      const char* unit;
    };
    const std::array<Field, 6> fields{{
        {f::kStiffness, "stiffness", m.stiffness_n_per_m, limits_.max_stiffness_n_per_m, " N/m"},
        {f::kMaxPenetration, "max depth", m.max_penetration_m, limits_.max_penetration_m, " m"},
        {f::kMaxForce, "max force", m.max_force_n, limits_.max_force_n, " N"},
        {f::kDamping, "damping", m.damping_n_s_per_m, limits_.max_damping_n_s_per_m, " N s/m"},
        {f::kStaticFriction, "static friction", m.static_friction, limits_.max_friction, ""},
        {f::kDynamicFriction, "dynamic friction", m.dynamic_friction, limits_.max_friction, ""},
    }};
    for (const Field& field : fields) {
      if ((m.material_fields & field.bit) != 0 &&
          check_value(true, field.value, field.limit) != ValueCheck::kOk) {
        char line[160];
        std::snprintf(line, sizeof line, "%s: %s %.6g%s is not within 0 .. %.6g%s", name.c_str(),
                      field.what, field.value, field.unit, field.limit, field.unit);
        return line;
      }
    }
  }
  switch (verdict) {
    case SampleVerdict::kOtherScene:
      return name + ": the command was made for another scene";
    case SampleVerdict::kStale:
      return name + ": the command was meant for an earlier start of this host";
    case SampleVerdict::kOutOfOrder:
      return name + ": not newer than this issuer's last command";
    default:
      return name;
  }
}

}  // namespace hapsim::net
