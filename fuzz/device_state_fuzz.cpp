// Fuzz target: raw bytes as a received hapsim_msg_DeviceState through net::DeviceStateGate (the
// simulation host's side: what may step the world). Checks, for any bytes:
//  * exactly one verdict per sample is counted;
//  * an accepted state is finite, within the gate's limits, with a unit quaternion and at most
//    kMaxFingers fingers, so the world never steps on a wild device;
//  * a refused state leaves the caller's sample untouched;
//  * the same sample twice is out of order the second time.
//
// Input layout (see fuzz/make_seed_corpus.py): a control byte, then the message's fields in IDL
// order (little-endian). Control bit 0 gives the sample the gate's device and scene.
#include "fuzz_support.h"
#include "hapsim/net/device_state_gate.h"

#include <cmath>

namespace {

constexpr std::uint16_t kDevice = 3;
constexpr std::uint64_t kSceneHash = 0x68617073696d2121ULL;

bool same(const hapsim::net::DeviceStateSample& a, const hapsim::net::DeviceStateSample& b) {
  return a.device_id == b.device_id && a.sequence == b.sequence &&
         a.input.p_world == b.input.p_world &&
         a.input.q_world.coeffs() == b.input.q_world.coeffs() &&
         a.input.finger_count == b.input.finger_count && a.input.finger_rad == b.input.finger_rad &&
         a.input.joint_count == b.input.joint_count && a.input.joint_rad == b.input.joint_rad &&
         a.v_world_m_per_s == b.v_world_m_per_s &&
         a.rendered.force_world_n == b.rendered.force_world_n &&
         a.rendered.finger_force_n == b.rendered.finger_force_n;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  hapsim::fuzz::FieldReader r(data, size);
  std::uint8_t control = 0;
  r.read(control);
  hapsim_msg_DeviceState m{};
  r.read(m.device_id);
  r.read(m.state_sequence);
  r.read(m.scene_hash);
  r.read(m.device_time_s);
  r.read(m.p_m);
  r.read(m.q_wxyz);
  r.read(m.v_m_per_s);
  r.read(m.finger_rad);
  r.read(m.finger_count);
  r.read(m.buttons);
  r.read_bool(m.healthy);
  r.read(m.rendered_force_n);
  r.read(m.rendered_finger_force_n);
  r.read(m.joint_rad);  // after the older fields: the committed seeds end before them
  r.read(m.joint_count);
  if ((control & 1U) != 0) {
    m.device_id = kDevice;
    m.scene_hash = kSceneHash;
  }

  const hapsim::net::DeviceStateLimits limits;
  hapsim::net::DeviceStateGate gate(kDevice, kSceneHash, limits);
  hapsim::net::DeviceStateSample sentinel;
  sentinel.device_id = 77;
  sentinel.sequence = 12345;
  sentinel.input.p_world = hapsim::Vec3(0.1, 0.2, 0.3);
  sentinel.rendered.finger_force_n[2] = 1.5;
  hapsim::net::DeviceStateSample out = sentinel;

  const hapsim::net::SampleVerdict verdict = gate.admit(m, out);
  std::uint64_t counted = 0;
  for (const std::uint64_t c : gate.counts()) {
    counted += c;
  }
  HAPSIM_FUZZ_CHECK(counted == 1, "one sample, one verdict");
  if (verdict != hapsim::net::SampleVerdict::kAccepted) {
    HAPSIM_FUZZ_CHECK(same(out, sentinel), "a refused state changed the caller's sample");
    return 0;
  }
  const hapsim::DeviceInput& in = out.input;
  HAPSIM_FUZZ_CHECK(
      in.p_world.allFinite() && in.p_world.cwiseAbs().maxCoeff() <= limits.max_position_m,
      "accepted position not finite or beyond the limit");
  HAPSIM_FUZZ_CHECK(std::abs(in.q_world.norm() - 1.0) < 1e-12, "accepted orientation not unit");
  HAPSIM_FUZZ_CHECK(out.v_world_m_per_s.allFinite() &&
                        out.v_world_m_per_s.cwiseAbs().maxCoeff() <= limits.max_speed_m_per_s,
                    "accepted velocity not finite or beyond the limit");
  HAPSIM_FUZZ_CHECK(in.finger_count >= 0 && in.finger_count <= hapsim::kMaxFingers,
                    "accepted finger count out of range");
  for (const double a : in.finger_rad) {
    HAPSIM_FUZZ_CHECK(std::isfinite(a), "accepted finger angle not finite");
  }
  HAPSIM_FUZZ_CHECK(in.joint_count >= 0 && in.joint_count <= hapsim::kMaxDeviceJoints,
                    "accepted joint count out of range");
  for (const double a : in.joint_rad) {
    HAPSIM_FUZZ_CHECK(std::isfinite(a), "accepted joint angle not finite");
  }
  HAPSIM_FUZZ_CHECK(out.rendered.force_world_n.allFinite() &&
                        out.rendered.force_world_n.cwiseAbs().maxCoeff() <= limits.max_force_n,
                    "accepted rendered force not finite or beyond the limit");
  for (const double f : out.rendered.finger_force_n) {
    HAPSIM_FUZZ_CHECK(std::isfinite(f) && std::abs(f) <= limits.max_force_n,
                      "accepted rendered finger force not finite or beyond the limit");
  }
  hapsim::net::DeviceStateSample again = sentinel;
  HAPSIM_FUZZ_CHECK(gate.admit(m, again) == hapsim::net::SampleVerdict::kOutOfOrder,
                    "the same state twice was not out of order");
  HAPSIM_FUZZ_CHECK(same(again, sentinel), "an out-of-order state changed the caller's sample");
  return 0;
}
