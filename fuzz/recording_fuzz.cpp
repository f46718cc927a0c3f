// Fuzz target: bytes as a recording file (read_recording: header, frames, checksums). The bytes
// go through a scratch file, so the checksums are mostly wrong; the seeds are real recordings
// and the replay's mutations keep their checksums only by chance, so a second mode (first byte
// odd) re-seals the header's and every frame's (block's, version 3) checksum before the read, to
// reach the frame checks. Checks: it
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

std::uint32_t u32_at(const std::string& bytes, std::size_t at) {
  std::uint32_t v = 0;
  std::memcpy(&v, bytes.data() + at, 4);
  return v;
}

void seal(std::string& bytes, std::size_t from, std::size_t length, std::size_t checksum_at) {
  const std::uint64_t h =
      fnv1a(reinterpret_cast<const unsigned char*>(bytes.data() + from), length);
  std::memcpy(bytes.data() + checksum_at, &h, 8);
}

// Rewrites the header's checksum, then every whole frame's (versions 1 and 2) or every whole
// block's (version 3: marker, count, length, frames, checksum), as docs/recording-format.md
// lays them out.
void reseal(std::string& bytes) {
  constexpr std::size_t kFixed = 8 + 6 * 4;  // magic, version, sizes, the hash's length
  if (bytes.size() < kFixed) {
    return;
  }
  const std::uint32_t version = u32_at(bytes, 8);
  std::size_t header = kFixed;
  for (int field = 0; field < (version >= 2 ? 3 : 1); ++field) {  // hash (and the two paths)
    if (bytes.size() < header + (field == 0 ? 0 : 4)) {
      return;
    }
    const std::size_t length_at = field == 0 ? kFixed - 4 : header;
    const std::uint32_t length = u32_at(bytes, length_at);
    if (length > 4096) {
      return;
    }
    header = (field == 0 ? kFixed : header + 4) + length;
  }
  if (bytes.size() < header + 8) {
    return;
  }
  seal(bytes, 0, header, header);
  std::size_t at = header + 8;
  if (version < 3) {
    const std::size_t frame = hapsim::recorded_frame_size_bytes();
    for (; at + frame <= bytes.size(); at += frame) {
      seal(bytes, at + 4, frame - 12, at + frame - 8);
    }
    return;
  }
  while (at + 12 <= bytes.size()) {
    const std::size_t length = u32_at(bytes, at + 8);
    if (length > bytes.size() || at + 12 + length + 8 > bytes.size()) {
      return;
    }
    seal(bytes, at, 12 + length, at + 12 + length);
    at += 12 + length + 8;
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
