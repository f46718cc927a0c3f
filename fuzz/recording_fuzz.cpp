// Fuzz target: bytes as a recording file (read_recording: header, frames, checksums). The bytes
// go through a scratch file, so the checksums are mostly wrong; the seeds are real recordings
// and the replay's mutations keep their checksums only by chance, so a second mode (first byte
// odd) re-seals every frame's checksum before the read, to reach the frame checks. Checks: it
// returns frames whose counts are in range and whose inputs and commands are finite, or throws
// hapsim::Error; nothing else escapes.
#include "file_fuzz_support.h"
#include "hapsim/device/recording.h"

#include <cmath>
#include <cstring>
#include <string>

namespace {

std::uint64_t fnv1a(const unsigned char* data, std::size_t size) {
  std::uint64_t h = 0xcbf29ce484222325ULL;
  for (std::size_t i = 0; i < size; ++i) {
    h = (h ^ data[i]) * 0x100000001b3ULL;
  }
  return h;
}

// Rewrites the header's and every whole frame's checksum (docs/recording-format.md).
void reseal(std::string& bytes) {
  constexpr std::size_t kFixed = 8 + 6 * 4;
  if (bytes.size() < kFixed) {
    return;
  }
  std::uint32_t hash_length = 0;
  std::memcpy(&hash_length, bytes.data() + kFixed - 4, 4);
  const std::size_t header = kFixed + hash_length;
  if (hash_length > 4096 || bytes.size() < header + 8) {
    return;
  }
  const std::uint64_t h = fnv1a(reinterpret_cast<const unsigned char*>(bytes.data()), header);
  std::memcpy(bytes.data() + header, &h, 8);
  const std::size_t frame = hapsim::recorded_frame_size_bytes();
  for (std::size_t at = header + 8; at + frame <= bytes.size(); at += frame) {
    const std::uint64_t f =
        fnv1a(reinterpret_cast<const unsigned char*>(bytes.data() + at + 4), frame - 12);
    std::memcpy(bytes.data() + at + frame - 8, &f, 8);
  }
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  if (size < 1) {
    return 0;
  }
  std::string bytes(hapsim::fuzz::as_text(data + 1, size - 1));
  if ((data[0] & 1) != 0) {
    reseal(bytes);
  }
  const auto path = hapsim::fuzz::scratch_file("fuzz.hrec", bytes);
  hapsim::fuzz::expect_value_or_error([&] {
    const hapsim::Recording r = hapsim::read_recording(path);
    for (const hapsim::RecordedFrame& f : r.frames) {
      HAPSIM_FUZZ_CHECK(f.input.finger_count >= 0 && f.input.finger_count <= hapsim::kMaxFingers,
                        "finger count in range");
      HAPSIM_FUZZ_CHECK(f.contact_count >= 0 && f.contact_count <= hapsim::kMaxRecordedContacts,
                        "contact count in range");
      HAPSIM_FUZZ_CHECK(f.input.p_world.allFinite() && std::isfinite(f.input.time_s) &&
                            f.command.force_world_n.allFinite(),
                        "inputs and commands are finite");
    }
  });
  return 0;
}
