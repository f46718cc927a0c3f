// Fuzz target: legacy force packets (device/legacy_force_codec.h) into the legacy glove
// (device/legacy_glove_device.h). Checks, for any bytes:
//  * the decoder's verdict is the one computed here from the bytes (16 bytes, each big-endian
//    int32 in 0..10 000), and a refused packet leaves the output untouched;
//  * the input cut into a stream of datagrams and drained by the glove never gives a NaN or a
//    finger force outside [0, max]; it renders the newest valid forces while healthy, zero
//    otherwise; every datagram is counted once;
//  * encoding any four doubles decodes to forces in [0, max], within half a step when in range.
#include "fuzz_support.h"
#include "hapsim/core/device_profile.h"
#include "hapsim/device/legacy_force_codec.h"
#include "hapsim/device/legacy_glove_device.h"

#include <cmath>
#include <memory>
#include <optional>
#include <span>
#include <vector>

namespace {

using hapsim::LegacyFingerForces;
using hapsim::LegacyPacketVerdict;

constexpr double kMaxN = 4.0;  // the Rutgers Master's finger rating

// Datagrams taken from a list, as a socket would hand them over.
class ListSource final : public hapsim::LegacyPacketSource {
 public:
  explicit ListSource(const std::vector<std::span<const std::byte>>* datagrams)
      : datagrams_(datagrams) {}
  std::optional<std::size_t> receive(std::span<std::byte> buffer) noexcept override {
    if (next_ >= limit_ || next_ >= datagrams_->size()) {
      return std::nullopt;
    }
    const std::span<const std::byte> d = (*datagrams_)[next_++];
    for (std::size_t i = 0; i < d.size() && i < buffer.size(); ++i) {
      buffer[i] = d[i];
    }
    return d.size();
  }
  void release_until(std::size_t limit) { limit_ = limit; }
  [[nodiscard]] std::size_t delivered() const { return next_; }

 private:
  const std::vector<std::span<const std::byte>>* datagrams_;
  std::size_t next_ = 0;
  std::size_t limit_ = 0;
};

void check_decoder(std::span<const std::byte> bytes) {
  LegacyPacketVerdict expected = LegacyPacketVerdict::kAccepted;
  std::int64_t values[4] = {};
  if (bytes.size() < 16) {
    expected = LegacyPacketVerdict::kShort;
  } else if (bytes.size() > 16) {
    expected = LegacyPacketVerdict::kLong;
  } else {
    for (std::size_t i = 0; i < 4; ++i) {
      std::int64_t v = 0;
      for (std::size_t b = 0; b < 4; ++b) {
        v = v * 256 + std::to_integer<int>(bytes[4 * i + b]);
      }
      values[i] = v >= (std::int64_t{1} << 31) ? v - (std::int64_t{1} << 32) : v;
      if (values[i] < 0 || values[i] > 10'000) {
        expected = LegacyPacketVerdict::kOutOfRange;
      }
    }
  }
  const LegacyFingerForces sentinel{-7.0, -7.0, -7.0, -7.0};
  LegacyFingerForces out = sentinel;
  const LegacyPacketVerdict verdict = hapsim::decode_legacy_force(bytes, kMaxN, out);
  HAPSIM_FUZZ_CHECK(verdict == expected, "decoder verdict differs from the packet's bytes");
  if (verdict != LegacyPacketVerdict::kAccepted) {
    HAPSIM_FUZZ_CHECK(out == sentinel, "a refused packet changed the output");
    return;
  }
  for (std::size_t i = 0; i < 4; ++i) {
    HAPSIM_FUZZ_CHECK(out[i] >= 0.0 && out[i] <= kMaxN, "decoded force outside [0, max]");
    HAPSIM_FUZZ_CHECK(std::abs(out[i] - kMaxN * static_cast<double>(values[i]) / 10'000.0) < 1e-12,
                      "decoded force is not value / 10 000 of the maximum");
  }
}

void check_glove_stream(const std::uint8_t* data, std::size_t size) {
  // Datagrams: a length byte (0..23: short, exact and long ones), then that many bytes.
  std::vector<std::span<const std::byte>> datagrams;
  for (std::size_t pos = 0; pos < size;) {
    const std::size_t length = data[pos] % 24;
    ++pos;
    const std::size_t n = length < size - pos ? length : size - pos;
    datagrams.emplace_back(reinterpret_cast<const std::byte*>(data + pos), n);
    pos += n;
  }
  auto source = std::make_unique<ListSource>(&datagrams);
  ListSource* list = source.get();
  hapsim::LegacyGloveOptions options;
  options.max_datagrams_per_read = 3;  // small, so draining over several reads is exercised
  hapsim::LegacyGloveDevice glove(hapsim::device_profile("rutgers_master"), std::move(source),
                                  options);
  double t = 0.0;
  for (std::size_t released = 0; released <= datagrams.size() + 3; released += 2) {
    list->release_until(released);
    const hapsim::DeviceInput in = glove.read(t);
    std::uint64_t judged = 0;
    for (const std::uint64_t c : glove.counts()) {
      judged += c;
    }
    HAPSIM_FUZZ_CHECK(judged == list->delivered(), "a datagram was not judged exactly once");
    const hapsim::DeviceCommand& rendered = glove.rendered();
    for (std::size_t i = 0; i < 4; ++i) {
      const double f = rendered.finger_force_n[i];
      HAPSIM_FUZZ_CHECK(std::isfinite(f) && f >= 0.0 && f <= kMaxN, "rendered force out of range");
      HAPSIM_FUZZ_CHECK(f == (in.healthy ? glove.newest_finger_force_n()[i] : 0.0),
                        "rendered force is neither the newest packet's nor zero");
    }
    HAPSIM_FUZZ_CHECK(rendered.force_world_n == hapsim::Vec3::Zero(), "a glove has no tool force");
    HAPSIM_FUZZ_CHECK(in.p_world.allFinite(), "glove pose not finite");
    t += 0.04;  // a few reads in, the newest packet goes stale
  }
}

void check_round_trip(const std::uint8_t* data, std::size_t size) {
  hapsim::fuzz::FieldReader r(data, size);
  LegacyFingerForces forces{};
  double max_n = 0.0;
  for (double& f : forces) {
    r.read(f);
  }
  r.read(max_n);
  const hapsim::LegacyEncoded encoded = hapsim::encode_legacy_force(forces, max_n);
  LegacyFingerForces out{};
  const LegacyPacketVerdict verdict = hapsim::decode_legacy_force(encoded.packet, max_n, out);
  if (!(std::isfinite(max_n) && max_n > 0.0)) {
    HAPSIM_FUZZ_CHECK(encoded.clamped_fingers == 4, "no usable maximum must clamp every finger");
    HAPSIM_FUZZ_CHECK(verdict == LegacyPacketVerdict::kOutOfRange, "no usable maximum decoded");
    return;
  }
  HAPSIM_FUZZ_CHECK(verdict == LegacyPacketVerdict::kAccepted, "an encoded packet was refused");
  for (std::size_t i = 0; i < 4; ++i) {
    HAPSIM_FUZZ_CHECK(std::isfinite(out[i]) && out[i] >= 0.0 && out[i] <= max_n,
                      "round trip outside [0, max]");
    if (std::isfinite(forces[i]) && forces[i] >= 0.0 && forces[i] <= max_n) {
      HAPSIM_FUZZ_CHECK(std::abs(out[i] - forces[i]) <= max_n * (0.5 / 10'000.0 + 1e-12),
                        "round trip further than half a step");
    }
  }
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  check_decoder(std::span<const std::byte>(reinterpret_cast<const std::byte*>(data), size));
  check_glove_stream(data, size);
  check_round_trip(data, size);
  return 0;
}
