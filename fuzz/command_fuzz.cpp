// Fuzz target: raw bytes as a received hapsim_msg_Command through net::CommandGate (the
// simulation host's side: what may pause, reset or retune the served world). Checks, for any
// bytes:
//  * exactly one verdict per sample is counted;
//  * an accepted command is a known kind; a material change names a material the scene has, sets
//    only known fields, and every value it sets is finite and within the gate's limits, so the
//    material it makes (apply_material_fields) is finite;
//  * the same command twice is out of order the second time.
//
// Input layout (see fuzz/make_seed_corpus.py): a control byte, then the message's fields in IDL
// order (little-endian). Control bit 0 gives the sample the gate's scene and host start.
#include "fuzz_support.h"
#include "hapsim/net/session_command.h"

#include <cmath>

namespace {

constexpr std::uint64_t kSceneHash = 0x68617073696d2121ULL;
constexpr std::uint64_t kServeId = 0x5e5e5e5e5e5e5e5eULL;
constexpr std::size_t kMaterials = 4;

bool finite(const hapsim::ContactMaterial& c) {
  return std::isfinite(c.stiffness_n_per_m) && std::isfinite(c.max_penetration_m) &&
         std::isfinite(c.max_force_n) && std::isfinite(c.damping_n_s_per_m) &&
         std::isfinite(c.static_friction) && std::isfinite(c.dynamic_friction);
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using hapsim::net::SampleVerdict;
  using hapsim::net::SessionCommandKind;
  hapsim::fuzz::FieldReader r(data, size);
  std::uint8_t control = 0;
  r.read(control);
  hapsim_msg_Command m{};
  r.read(m.issuer_id);
  r.read(m.command_sequence);
  r.read(m.scene_hash);
  r.read(m.serve_id);
  r.read(m.kind);
  r.read(m.material);
  r.read(m.material_fields);
  r.read(m.stiffness_n_per_m);
  r.read(m.max_penetration_m);
  r.read(m.max_force_n);
  r.read(m.damping_n_s_per_m);
  r.read(m.static_friction);
  r.read(m.dynamic_friction);
  if ((control & 1U) != 0) {
    m.scene_hash = kSceneHash;
    m.serve_id = kServeId;
  }

  const hapsim::net::CommandLimits limits;
  hapsim::net::CommandGate gate(kSceneHash, kServeId, kMaterials, limits);
  hapsim::net::SessionCommand out;
  const SampleVerdict verdict = gate.admit(m, out);
  std::uint64_t counted = 0;
  for (const std::uint64_t c : gate.counts()) {
    counted += c;
  }
  HAPSIM_FUZZ_CHECK(counted == 1, "one sample, one verdict");
  if (verdict != SampleVerdict::kAccepted) {
    return 0;
  }
  HAPSIM_FUZZ_CHECK(m.scene_hash == kSceneHash && m.serve_id == kServeId,
                    "accepted a command for another scene or host start");
  HAPSIM_FUZZ_CHECK(hapsim::net::command_kind(hapsim::net::command_name(out.kind)).has_value(),
                    "accepted an unknown kind");
  if (out.kind == SessionCommandKind::kSetMaterial) {
    HAPSIM_FUZZ_CHECK(out.material < kMaterials, "accepted a material the scene does not have");
    HAPSIM_FUZZ_CHECK(
        out.material_fields != 0 && (out.material_fields & ~hapsim::net::material_field::kAll) == 0,
        "accepted unknown or no fields");
    const hapsim::ContactMaterial made =
        hapsim::net::apply_material_fields(hapsim::ContactMaterial{}, out);
    HAPSIM_FUZZ_CHECK(finite(made), "an accepted change made a non-finite material");
    HAPSIM_FUZZ_CHECK(made.stiffness_n_per_m >= 0.0 &&
                          made.stiffness_n_per_m <= limits.max_stiffness_n_per_m &&
                          made.max_force_n >= 0.0 && made.max_force_n <= limits.max_force_n,
                      "an accepted change is beyond the limits");
  }
  hapsim::net::SessionCommand again;
  HAPSIM_FUZZ_CHECK(gate.admit(m, again) == SampleVerdict::kOutOfOrder,
                    "the same command twice was not out of order");
  return 0;
}
