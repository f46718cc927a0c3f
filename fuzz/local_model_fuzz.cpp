// Fuzz target: raw bytes as a received hapsim_msg_LocalModel, through net::LocalModelGate, then
// (when accepted) into a LocalModelRenderer that was already rendering a contact. Checks:
//  * exactly one verdict is counted;
//  * an accepted model decodes to finite fields;
//  * whatever arrives, every rendered force (at fixed probes, at the sample's own x0 and at a
//    probe taken from the bytes, NaN included) is finite and within the renderer's clamp;
//  * a sample the gate refuses (or the renderer refuses) never changes the rendered force: a
//    twin renderer that never saw it renders the same, bit for bit.
//
// Input layout (see fuzz/make_seed_corpus.py): a control byte, the message's fields in IDL order
// (little-endian, as deserialized), then the device's own newest sequence and a probe position.
// Control bit 0 gives the sample the gate's device and scene (so deep paths are reached without
// guessing a 64-bit hash), bit 1 makes the device's sequence the sample's plus (control >> 3),
// bit 2 folds the finger into 0..2 (two valid fingers and one beyond).
#include "fuzz_support.h"
#include "hapsim/device/local_model_renderer.h"
#include "hapsim/net/local_model_gate.h"

#include <cmath>
#include <cstring>

namespace {

constexpr std::uint16_t kDevice = 3;
constexpr std::uint64_t kSceneHash = 0x68617073696d2121ULL;
constexpr double kMaxForceN = 10.0;

hapsim::LocalContactModel pressing_contact() {
  hapsim::LocalContactModel m;
  m.x0_world_m = hapsim::Vec3(0.0, 0.0, 0.0);
  m.f0_world_n = hapsim::Vec3(0.0, 0.0, 2.0);
  m.stiffness_n_per_m = hapsim::Mat3::Identity() * 1000.0;
  m.damping_n_s_per_m = hapsim::Mat3::Identity() * 1.0;
  m.normal_world = hapsim::Vec3::UnitZ();
  m.validity_radius_m = 0.05;
  m.sequence = 1;
  m.device_sequence = 1;
  m.valid = true;
  return m;
}

bool same_bits(const hapsim::Vec3& a, const hapsim::Vec3& b) {
  return std::memcmp(a.data(), b.data(), 3 * sizeof(double)) == 0;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  hapsim::fuzz::FieldReader r(data, size);
  std::uint8_t control = 0;
  r.read(control);
  hapsim_msg_LocalModel m{};
  r.read(m.device_id);
  r.read(m.finger);
  r.read(m.model_sequence);
  r.read(m.device_sequence);
  r.read(m.scene_hash);
  r.read(m.sim_time_s);
  r.read(m.x0_m);
  r.read(m.v0_m_per_s);
  r.read(m.f0_n);
  r.read(m.stiffness_n_per_m);
  r.read(m.damping_n_s_per_m);
  r.read(m.normal);
  r.read(m.validity_radius_m);
  r.read_bool(m.valid);
  std::uint64_t device_sequence_now = 0;
  r.read(device_sequence_now);
  double probe[3] = {};
  r.read(probe);
  r.read(m.max_normal_force_n);  // after the older fields: the committed seeds end before it
  r.read(m.profile_count);       // and the profile after that
  r.read(m.profile_depth_m);
  r.read(m.profile_push_n);
  if ((control & 1U) != 0) {
    m.device_id = kDevice;
    m.scene_hash = kSceneHash;
  }
  if ((control & 2U) != 0) {
    device_sequence_now = m.device_sequence + (control >> 3U);
  }
  if ((control & 4U) != 0) {
    m.finger = static_cast<std::uint16_t>(m.finger % 3U);
  }

  hapsim::net::LocalModelGate gate(kDevice, kSceneHash, 2);
  hapsim::LocalModelRenderOptions options;
  options.max_force_n = kMaxForceN;
  hapsim::LocalModelRenderer renderer(options);
  hapsim::LocalModelRenderer twin(options);
  const hapsim::LocalContactModel before = pressing_contact();
  renderer.receive(before, 0.0);
  twin.receive(before, 0.0);

  hapsim::LocalContactModel decoded;
  const hapsim::net::SampleVerdict verdict = gate.admit(m, device_sequence_now, decoded);
  std::uint64_t counted = 0;
  for (std::size_t v = 0; v < hapsim::net::kSampleVerdicts; ++v) {
    counted += gate.count(static_cast<hapsim::net::SampleVerdict>(v));
  }
  HAPSIM_FUZZ_CHECK(counted == 1, "one sample, one verdict");

  const double arrival_s = 0.05;
  bool may_change = false;
  if (verdict == hapsim::net::SampleVerdict::kAccepted) {
    HAPSIM_FUZZ_CHECK(decoded.x0_world_m.allFinite() && decoded.v0_world_m_per_s.allFinite() &&
                          decoded.f0_world_n.allFinite() && decoded.stiffness_n_per_m.allFinite() &&
                          decoded.damping_n_s_per_m.allFinite() &&
                          decoded.normal_world.allFinite() &&
                          std::isfinite(decoded.validity_radius_m),
                      "an accepted model has a non-finite field");
    const std::uint64_t refused = renderer.counts().models_refused;
    renderer.receive(decoded, arrival_s);
    may_change = renderer.counts().models_refused == refused;
  }

  const hapsim::Vec3 probes[] = {
      hapsim::Vec3(0.0, 0.0, -0.001),
      hapsim::Vec3(0.002, -0.001, -0.004),
      hapsim::Vec3(m.x0_m[0], m.x0_m[1], m.x0_m[2]),
      hapsim::Vec3(probe[0], probe[1], probe[2]),
  };
  const hapsim::Vec3 velocities[] = {
      hapsim::Vec3::Zero(), hapsim::Vec3(m.v0_m_per_s[0], m.v0_m_per_s[1], m.v0_m_per_s[2])};
  for (const double t : {arrival_s, arrival_s + 0.01, arrival_s + 0.03, 0.2, 1.0}) {
    for (const hapsim::Vec3& x : probes) {
      for (const hapsim::Vec3& v : velocities) {
        const hapsim::Vec3 f = renderer.render(x, v, t);
        const hapsim::Vec3 g = twin.render(x, v, t);
        HAPSIM_FUZZ_CHECK(f.allFinite(), "rendered a non-finite force");
        HAPSIM_FUZZ_CHECK(f.norm() <= kMaxForceN * (1.0 + 1e-12), "rendered beyond the clamp");
        if (!may_change) {
          HAPSIM_FUZZ_CHECK(same_bits(f, g), "a refused sample changed the rendered force");
        }
      }
    }
  }
  return 0;
}
