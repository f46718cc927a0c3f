#include "hapsim/device/recording.h"

#include "hapsim/core/error.h"
#include "hapsim/device/force_safety.h"
#include "hapsim/device/simulated_device.h"
#include "support/temp_path.h"

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstring>
#include <fstream>
#include <limits>
#include <numbers>

#include <gtest/gtest.h>

namespace hapsim {
namespace {

// Frames with awkward values: -0.0, a denormal, a NaN with a payload, large and tiny numbers.
RecordedFrame make_frame(std::uint64_t i) {
  RecordedFrame f;
  const double x = static_cast<double>(i);
  f.cycle_index = i;
  f.input.time_s = 0.001 * x;
  f.input.p_world = Vec3(std::sin(x) / 3.0, -0.0, 1e-310 * x);
  f.input.q_world = Quat(Eigen::AngleAxisd(0.01 * x, Vec3(1, 1, 0).normalized()));
  f.input.finger_count = 2;
  f.input.finger_rad = {std::numbers::pi / (x + 1), 1.0 / 3.0, 0, 0, 0};
  f.input.joint_count = 1;
  f.input.joint_rad[0] = -x * 1e10;
  f.input.buttons = static_cast<std::uint32_t>(i % 4);
  f.input.healthy = i % 5 != 4;
  f.command.force_world_n = Vec3(0.1 * x, -0.2, std::sqrt(x));
  f.command.finger_count = 2;
  f.command.finger_force_n = {0.5, 1.0 / 7.0, 0, 0, 0};
  f.command.joint_count = 1;
  f.command.joint_torque_nm[0] = 1e-3 * x;
  f.contact_count = static_cast<std::int32_t>(i % 3);
  for (int c = 0; c < f.contact_count; ++c) {
    RecordedContact& k = f.contacts[static_cast<std::size_t>(c)];
    k.tool_index = c;
    k.body_index = 7;
    k.segment_index = c - 1;
    k.point_world = Vec3(x, 2.0 / 3.0, -1.0);
    k.normal_world = Vec3::UnitZ();
    k.depth_m = 1e-4 * x;
    k.force_n = std::bit_cast<double>(0x7ff8'0000'0000'1234ull);  // NaN with a payload
  }
  return f;
}

std::vector<RecordedFrame> make_frames(std::size_t n) {
  std::vector<RecordedFrame> frames;
  for (std::size_t i = 0; i < n; ++i) {
    frames.push_back(make_frame(i));
  }
  return frames;
}

// Every double of the frame, in a fixed order, for memcmp.
std::vector<double> doubles_of(const RecordedFrame& f) {
  std::vector<double> d = {f.input.time_s};
  d.insert(d.end(), f.input.p_world.data(), f.input.p_world.data() + 3);
  d.insert(d.end(), f.input.q_world.coeffs().data(), f.input.q_world.coeffs().data() + 4);
  d.insert(d.end(), f.input.joint_rad.begin(), f.input.joint_rad.end());
  d.insert(d.end(), f.input.finger_rad.begin(), f.input.finger_rad.end());
  d.insert(d.end(), f.command.force_world_n.data(), f.command.force_world_n.data() + 3);
  d.insert(d.end(), f.command.finger_force_n.begin(), f.command.finger_force_n.end());
  d.insert(d.end(), f.command.joint_torque_nm.begin(), f.command.joint_torque_nm.end());
  for (const RecordedContact& c : f.contacts) {
    d.insert(d.end(), c.point_world.data(), c.point_world.data() + 3);
    d.insert(d.end(), c.normal_world.data(), c.normal_world.data() + 3);
    d.push_back(c.depth_m);
    d.push_back(c.force_n);
  }
  return d;
}

void expect_bit_identical(const RecordedFrame& a, const RecordedFrame& b) {
  const std::vector<double> da = doubles_of(a);
  const std::vector<double> db = doubles_of(b);
  ASSERT_EQ(da.size(), db.size());
  EXPECT_EQ(std::memcmp(da.data(), db.data(), da.size() * sizeof(double)), 0);
  EXPECT_EQ(a.cycle_index, b.cycle_index);
  EXPECT_EQ(a.input.buttons, b.input.buttons);
  EXPECT_EQ(a.input.healthy, b.input.healthy);
  EXPECT_EQ(a.input.finger_count, b.input.finger_count);
  EXPECT_EQ(a.command.joint_count, b.command.joint_count);
  EXPECT_EQ(a.contact_count, b.contact_count);
  for (std::size_t c = 0; c < a.contacts.size(); ++c) {
    EXPECT_EQ(a.contacts[c].segment_index, b.contacts[c].segment_index);
  }
}

std::filesystem::path write_recording(const std::vector<RecordedFrame>& frames,
                                      const std::string& hash = "scene-abc123") {
  const auto path = test::temp_path(".hrec");
  SessionRecorder recorder(path, hash, 7, SessionRecorder::Overflow::kFlushInline);
  for (const RecordedFrame& f : frames) {
    EXPECT_TRUE(recorder.record(f));
  }
  recorder.close();
  EXPECT_EQ(recorder.frames_written(), frames.size());
  EXPECT_EQ(recorder.frames_dropped(), 0u);
  return path;
}

std::vector<char> file_bytes(const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

void write_bytes(const std::filesystem::path& path, const std::vector<char>& bytes) {
  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  out.write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
}

// The message of the hapsim::Error that reading `path` throws ("" if it does not throw).
std::string read_error(const std::filesystem::path& path) {
  try {
    (void)read_recording(path);
  } catch (const Error& e) {
    EXPECT_EQ(e.where(), path.string());
    return e.what();
  }
  return "";
}

// Versions 2 and 3: magic, six counts, the hash, two scene paths (empty here: a length each),
// checksum.
std::size_t header_size(const std::string& hash) {
  return 8 + 6 * 4 + hash.size() + 4 + 4 + 8;
}

// A version 3 block's bytes around its frames: marker, count, length, checksum.
constexpr std::size_t kBlockOverhead = 4 + 4 + 4 + 8;

std::uint64_t fnv1a(const char* data, std::size_t size) {
  std::uint64_t h = 0xcbf29ce484222325ull;
  for (std::size_t i = 0; i < size; ++i) {
    h ^= static_cast<unsigned char>(data[i]);
    h *= 0x100000001b3ull;
  }
  return h;
}

template <class T>
void append(std::vector<char>& out, const T& value) {
  const auto* p = reinterpret_cast<const char*>(&value);
  out.insert(out.end(), p, p + sizeof(T));
}

// The same session as versions 1 and 2 wrote it, from a version 3 file with empty scene paths,
// written here from docs/recording-format.md (not with the library's encoder): the header without
// (v1) or with (v2) the path fields, then each frame as "HFR1", its fields, FNV-1a 64 of them.
std::vector<char> as_old_version(const std::vector<char>& v3, const std::string& hash,
                                 std::uint32_t version) {
  const std::size_t hash_end = 8 + 6 * 4 + hash.size();
  const std::size_t payload = recorded_frame_payload_bytes();
  std::vector<char> out(v3.begin(), v3.begin() + static_cast<std::ptrdiff_t>(hash_end));
  std::memcpy(out.data() + 8, &version, 4);
  const auto frame_size = static_cast<std::uint32_t>(payload + 12);
  std::memcpy(out.data() + 12, &frame_size, 4);
  if (version == 2) {
    append(out, std::uint32_t{0});
    append(out, std::uint32_t{0});
  }
  append(out, fnv1a(out.data(), out.size()));
  for (std::size_t at = header_size(hash); at < v3.size();) {
    std::uint32_t count = 0;
    std::memcpy(&count, v3.data() + at + 4, 4);
    for (std::size_t i = 0; i < count; ++i) {
      const char* fields = v3.data() + at + 12 + i * payload;
      out.insert(out.end(), {'H', 'F', 'R', '1'});
      out.insert(out.end(), fields, fields + payload);
      append(out, fnv1a(fields, payload));
    }
    at += kBlockOverhead + count * payload;
  }
  return out;
}

TEST(Recording, RoundTripIsBitExact) {
  const auto frames = make_frames(23);  // 3 full buffers of 7 and a partial one
  const auto path = write_recording(frames);
  // Blocks of 7, 7, 7 and 2 frames (a flush each).
  EXPECT_EQ(std::filesystem::file_size(path), header_size("scene-abc123") +
                                                  frames.size() * recorded_frame_payload_bytes() +
                                                  4 * kBlockOverhead);
  const Recording rec = read_recording(path);
  std::filesystem::remove(path);
  EXPECT_EQ(rec.header.version, kRecordingVersion);
  EXPECT_EQ(rec.header.scene_hash, "scene-abc123");
  EXPECT_EQ(rec.header.frame_size_bytes, recorded_frame_payload_bytes());
  ASSERT_EQ(rec.frames.size(), frames.size());
  for (std::size_t i = 0; i < frames.size(); ++i) {
    SCOPED_TRACE(i);
    expect_bit_identical(rec.frames[i], frames[i]);
  }
  EXPECT_TRUE(compare_frames(frames, rec.frames).identical);
}

TEST(Recording, RealTimeBufferDropsInsteadOfBlockingAndCounts) {
  const auto path = test::temp_path(".hrec");
  {
    SessionRecorder recorder(path, "h", 4);  // Overflow::kDrop
    for (std::uint64_t i = 0; i < 6; ++i) {
      EXPECT_EQ(recorder.record(make_frame(i)), i < 4) << i;
    }
    EXPECT_EQ(recorder.frames_buffered(), 4u);
    EXPECT_EQ(recorder.frames_dropped(), 2u);
    recorder.flush();
    EXPECT_EQ(recorder.frames_written(), 4u);
    EXPECT_TRUE(recorder.record(make_frame(9)));
    RecordedFrame bad = make_frame(10);
    bad.contact_count = kMaxRecordedContacts + 1;  // would make an unreadable file
    EXPECT_FALSE(recorder.record(bad));
    EXPECT_EQ(recorder.frames_dropped(), 3u);
  }  // the destructor flushes
  const Recording rec = read_recording(path);
  std::filesystem::remove(path);
  ASSERT_EQ(rec.frames.size(), 5u);
  EXPECT_EQ(rec.frames[4].cycle_index, 9u);
}

// A run killed while writing leaves a torn end: every whole block before it is kept, with one
// warning on stderr naming the file and the frames kept. Cut at every byte of the last two blocks
// and through the rest in steps: the frames read are those of the whole blocks before the cut.
TEST(Recording, TornEndKeepsEveryWholeBlock) {
  const auto frames = make_frames(23);  // blocks of 7, 7, 7, 2
  const auto path = write_recording(frames);
  const auto original = file_bytes(path);
  const std::size_t header = header_size("scene-abc123");
  const std::size_t payload = recorded_frame_payload_bytes();
  const std::vector<std::size_t> block_frames = {7, 7, 7, 2};
  const auto torn = test::temp_path("_torn.hrec");
  // Every byte near a block's start or end and through the short last block, in steps elsewhere.
  std::vector<std::size_t> boundaries = {header};
  for (const std::size_t n : block_frames) {
    boundaries.push_back(boundaries.back() + n * payload + kBlockOverhead);
  }
  ASSERT_EQ(boundaries.back(), original.size());
  const auto step_after = [&](std::size_t cut) -> std::size_t {
    for (const std::size_t b : boundaries) {
      if (cut + 24 >= b && cut <= b + 24) {
        return 1;
      }
    }
    return cut >= boundaries[3] ? 7 : 53;
  };
  for (std::size_t cut = header; cut < original.size(); cut += step_after(cut)) {
    write_bytes(torn, {original.begin(), original.begin() + static_cast<std::ptrdiff_t>(cut)});
    std::size_t expected = 0;
    std::size_t end = header;
    for (const std::size_t n : block_frames) {
      end += n * payload + kBlockOverhead;
      if (end > cut) {
        break;
      }
      expected += n;
    }
    ::testing::internal::CaptureStderr();
    Recording rec;
    try {
      rec = read_recording(torn);
    } catch (const Error& e) {
      (void)::testing::internal::GetCapturedStderr();
      ADD_FAILURE() << "cut at " << cut << ": " << e.what();
      continue;
    }
    const std::string warning = ::testing::internal::GetCapturedStderr();
    ASSERT_EQ(rec.frames.size(), expected) << "cut at " << cut;
    EXPECT_TRUE(compare_frames({frames.data(), expected}, rec.frames).identical);
    std::size_t whole_end = header;
    for (std::size_t k = 0, n = 0; k < block_frames.size() && n < expected; ++k) {
      whole_end += block_frames[k] * payload + kBlockOverhead;
      n += block_frames[k];
    }
    if (cut == whole_end) {
      EXPECT_EQ(warning, "") << "cut at " << cut;  // ends after a whole block: a clean end
    } else {
      // One line: the file, the kept frames.
      EXPECT_NE(warning.find(torn.string()), std::string::npos) << warning;
      EXPECT_NE(warning.find("kept the " + std::to_string(expected) + " whole frame(s)"),
                std::string::npos)
          << warning;
      EXPECT_EQ(std::count(warning.begin(), warning.end(), '\n'), 1) << warning;
    }
  }
  // A header cut short is still an error: there is nothing to keep.
  auto bytes = original;
  bytes.resize(20);
  write_bytes(path, bytes);
  EXPECT_NE(read_error(path).find("too short for the header"), std::string::npos);
  bytes = original;
  bytes.resize(header - 3);
  write_bytes(path, bytes);
  EXPECT_NE(read_error(path).find("truncated header"), std::string::npos);
  bytes.clear();
  write_bytes(path, bytes);
  EXPECT_NE(read_error(path).find("too short"), std::string::npos);
  std::filesystem::remove(path);
  std::filesystem::remove(torn);
  EXPECT_NE(read_error(path).find("cannot open"), std::string::npos);
}

// A whole block that fails its checks is corruption, not a torn end: an error naming the block.
TEST(Recording, CorruptBlockNamesTheBlock) {
  const auto frames = make_frames(23);
  const auto path = write_recording(frames);
  const auto original = file_bytes(path);
  const std::size_t block_bytes = 7 * recorded_frame_payload_bytes() + kBlockOverhead;
  const std::size_t block1 = header_size("scene-abc123") + block_bytes;
  // Every single-byte flip anywhere in block 1 is caught (marker, count, length, fields or
  // checksum).
  for (std::size_t offset = 0; offset < block_bytes; offset += offset < 16 ? 1 : 37) {
    auto bytes = original;
    bytes[block1 + offset] = static_cast<char>(bytes[block1 + offset] ^ 0x10);
    write_bytes(path, bytes);
    const std::string message = read_error(path);
    EXPECT_NE(message.find("block at byte offset " + std::to_string(block1) + " (frame 7 on)"),
              std::string::npos)
        << offset << ": " << message;
    EXPECT_NE(message.find("corrupt"), std::string::npos) << message;
  }
  std::filesystem::remove(path);
}

// The version 1 and 2 layout: a frame at a time, each with its marker and checksum. A torn end
// keeps the whole frames; a corrupt frame is named.
TEST(Recording, OldVersionsStillReadTornOrCorrupt) {
  const auto frames = make_frames(6);
  const auto path = write_recording(frames);
  const auto v2 = as_old_version(file_bytes(path), "scene-abc123", 2);
  const std::size_t frame = recorded_frame_size_bytes();
  const std::size_t frame2 = header_size("scene-abc123") + 2 * frame;
  ASSERT_EQ(v2.size(), header_size("scene-abc123") + 6 * frame);
  write_bytes(path, v2);
  Recording rec = read_recording(path);
  EXPECT_EQ(rec.header.version, 2u);
  EXPECT_TRUE(compare_frames(frames, rec.frames).identical);

  auto bytes = v2;
  bytes.resize(frame2 + frame + frame / 2);
  write_bytes(path, bytes);
  ::testing::internal::CaptureStderr();
  rec = read_recording(path);
  const std::string warning = ::testing::internal::GetCapturedStderr();
  EXPECT_EQ(rec.frames.size(), 3u);
  EXPECT_NE(warning.find("kept the 3 whole frame(s)"), std::string::npos) << warning;

  // Every single-byte flip anywhere in frame 2 is caught (marker, payload or checksum).
  for (std::size_t offset = 0; offset < frame; offset += 37) {
    bytes = v2;
    bytes[frame2 + offset] = static_cast<char>(bytes[frame2 + offset] ^ 0x10);
    write_bytes(path, bytes);
    const std::string message = read_error(path);
    EXPECT_NE(message.find("frame 2 "), std::string::npos) << offset << ": " << message;
    EXPECT_NE(message.find("corrupt"), std::string::npos) << message;
  }
  std::filesystem::remove(path);
}

// A file the version 2 code wrote (hapsim run scenes/csg_block.json --duration 0.03 --record, at
// commit 0ae5a42): it still reads, whole.
TEST(Recording, AFileTheVersionTwoCodeWroteStillReads) {
  const std::filesystem::path file =
      std::filesystem::path(HAPSIM_SOURCE_DIR) / "tests/data/recordings/v2_csg_block_30_frames.rec";
  const Recording rec = read_recording(file);
  EXPECT_EQ(rec.header.version, 2u);
  EXPECT_EQ(rec.header.frame_size_bytes, recorded_frame_size_bytes());
  EXPECT_EQ(rec.header.scene_path, "/work/main/scenes/csg_block.json");
  ASSERT_EQ(rec.frames.size(), 30u);
  for (std::size_t i = 0; i < rec.frames.size(); ++i) {
    EXPECT_EQ(rec.frames[i].cycle_index, i);
    EXPECT_TRUE(rec.frames[i].input.healthy);
  }
  EXPECT_NEAR(rec.frames[29].input.time_s - rec.frames[0].input.time_s, 0.029, 1e-12);
}

// A streamed replay plays the file's frames in order, holds the last, and restarts on rewind;
// its memory is the ring, not the file.
TEST(ReplayDevice, StreamsAFileFrameByFrame) {
  const auto frames = make_frames(5000);  // more than the prefetch ring holds
  const auto path = write_recording(frames);
  const RecordingScan scan = scan_recording(path);
  ASSERT_EQ(scan.frames, 5000u);
  ReplayDevice device(device_profile("simulated"), path, scan.frames);
  for (int pass = 0; pass < 2; ++pass) {
    for (std::size_t i = 0; i < frames.size(); ++i) {
      const DeviceInput in = device.read(0.0);
      ASSERT_EQ(std::memcmp(&in.time_s, &frames[i].input.time_s, sizeof(double)), 0) << i;
      ASSERT_EQ(in.healthy, frames[i].input.healthy) << i;
    }
    EXPECT_TRUE(device.finished());
    EXPECT_EQ(device.read(0.0).time_s, frames.back().input.time_s);
    device.rewind();
  }
  EXPECT_TRUE(device.frames().empty());

  // The file shrinks after it was checked: the device says why and holds its last input.
  auto bytes = file_bytes(path);
  bytes.resize(header_size("scene-abc123") + 10 * (7 * recorded_frame_payload_bytes() + 20));
  write_bytes(path, bytes);
  ReplayDevice shrunk(device_profile("simulated"), path, scan.frames);
  for (std::size_t i = 0; i < 100; ++i) {
    (void)shrunk.read(0.0);
  }
  EXPECT_EQ(shrunk.status().health, DeviceHealth::kFailed);
  EXPECT_NE(std::string(shrunk.status().reason).find("fewer than the 5000"), std::string::npos)
      << shrunk.status().reason;
  std::filesystem::remove(path);
}

// A device's input is checked before it is recorded and the command is the world's, NaN zeroed:
// a recording holding a NaN input (made up, or corrupted with its checksum redone) replayed as
// "identical" before, proving nothing; now reading it names the frame and the field.
TEST(Recording, NonFiniteInputOrCommandIsRefused) {
  auto frames = make_frames(3);
  frames[1].input.p_world.x() = std::numeric_limits<double>::quiet_NaN();
  const auto path = write_recording(frames);
  const std::string message = read_error(path);
  EXPECT_NE(message.find("frame 1 "), std::string::npos) << message;
  EXPECT_NE(message.find("input.p_world[0] is nan"), std::string::npos) << message;

  frames = make_frames(3);
  frames[2].command.finger_force_n[1] = -std::numeric_limits<double>::infinity();
  const auto path2 = write_recording(frames);
  const std::string message2 = read_error(path2);
  EXPECT_NE(message2.find("frame 2 "), std::string::npos) << message2;
  EXPECT_NE(message2.find("command.finger_force_n[1] is -inf"), std::string::npos) << message2;
  std::filesystem::remove(path);
  std::filesystem::remove(path2);
}

TEST(Recording, CorruptHeaderIsRejected) {
  const auto path = write_recording(make_frames(2));
  const auto original = file_bytes(path);
  const auto with = [&](std::size_t offset, char value) {
    auto bytes = original;
    bytes[offset] = value;
    write_bytes(path, bytes);
    return read_error(path);
  };
  EXPECT_NE(with(0, 'X').find("bad magic"), std::string::npos);
  EXPECT_NE(with(8, 9).find("version 9"), std::string::npos);                    // version
  EXPECT_NE(with(12, 1).find("corrupt header: frame size"), std::string::npos);  // frame size
  EXPECT_NE(with(29, 0x7f).find("scene hash length"), std::string::npos);        // hash length
  // A plausible hash length: the scene paths' lengths are then read from the wrong place, and
  // either they or the checksum fail.
  EXPECT_NE(with(28, 100).find("corrupt header"), std::string::npos);  // plausible length
  EXPECT_NE(with(33, 'Z').find("checksum"), std::string::npos);        // hash text
  std::filesystem::remove(path);
}

// Version 2 names the scene (as given and absolute); a version 1 file (no paths) still reads.
TEST(Recording, TheHeaderNamesTheSceneAndVersionOneStillReads) {
  const auto frames = make_frames(3);
  const auto path = test::temp_path(".hrec");
  {
    SessionRecorder recorder(path, "scene-abc123", 7, SessionRecorder::Overflow::kFlushInline,
                             "scenes/knee_paper.json");
    for (const RecordedFrame& f : frames) {
      EXPECT_TRUE(recorder.record(f));
    }
    recorder.close();
  }
  const Recording rec = read_recording(path);
  EXPECT_EQ(rec.header.version, 3u);
  EXPECT_EQ(rec.header.scene_path, "scenes/knee_paper.json");
  EXPECT_EQ(rec.header.scene_path_absolute,
            (std::filesystem::current_path() / "scenes/knee_paper.json").string());
  EXPECT_EQ(rec.frames.size(), 3u);

  // The same session as version 1 wrote it: no path fields, frames one by one.
  const auto v3 = write_recording(frames);
  const auto v1 = test::temp_path("_v1.hrec");
  write_bytes(v1, as_old_version(file_bytes(v3), "scene-abc123", 1));
  const Recording old = read_recording(v1);
  EXPECT_EQ(old.header.version, 1u);
  EXPECT_EQ(old.header.scene_hash, "scene-abc123");
  EXPECT_EQ(old.header.scene_path, "");
  ASSERT_EQ(old.frames.size(), 3u);
  EXPECT_TRUE(compare_frames(frames, old.frames).identical);
  std::filesystem::remove(path);
  std::filesystem::remove(v1);
  std::filesystem::remove(v3);
}

TEST(Recording, CompareReportsTheFirstDifferingFrameAndField) {
  const auto expected = make_frames(10);
  auto actual = expected;
  EXPECT_TRUE(compare_frames(expected, actual).identical);

  actual[7].input.p_world.x() += 1.0;
  actual[5].command.finger_force_n[1] = std::nextafter(actual[5].command.finger_force_n[1], 1.0);
  RecordingDifference d = compare_frames(expected, actual);
  EXPECT_FALSE(d.identical);
  EXPECT_EQ(d.frame_index, 5u);
  EXPECT_EQ(d.field, "command.finger_force_n[1]");
  EXPECT_NE(d.message.find("frame 5, command.finger_force_n[1]: expected 0.14285714285714285"),
            std::string::npos)
      << d.message;

  actual = expected;
  actual[3].contacts[1].point_world.z() = -actual[3].contacts[1].point_world.z();
  d = compare_frames(expected, actual);
  EXPECT_EQ(d.frame_index, 3u);
  EXPECT_EQ(d.field, "contacts[1].point_world[2]");

  actual = expected;
  actual[0].input.p_world.y() = 0.0;  // was -0.0: equal as numbers, not as bits
  d = compare_frames(expected, actual);
  EXPECT_EQ(d.frame_index, 0u);
  EXPECT_EQ(d.field, "input.p_world[1]");

  actual = expected;
  actual.pop_back();
  d = compare_frames(expected, actual);
  EXPECT_FALSE(d.identical);
  EXPECT_EQ(d.frame_index, RecordingDifference::kNoFrame);
  EXPECT_EQ(d.field, "frame count");

  Recording a;
  a.header.scene_hash = "one";
  a.frames = expected;
  Recording b = a;
  b.header.scene_hash = "two";
  EXPECT_EQ(compare_recordings(a, b).field, "header.scene_hash");
}

// A toy deterministic step standing in for World::step: a spring towards the origin, clamped
// and safety-filtered like the real loop, with a contact when below z = 0.
RecordedFrame step(Device& device, std::uint64_t cycle, ForceWatchdog& watchdog) {
  constexpr double kDt = 0.001;
  RecordedFrame frame;
  frame.cycle_index = cycle;
  frame.input = device.read(static_cast<double>(cycle) * kDt);
  DeviceCommand wanted;
  wanted.force_world_n = -800.0 * frame.input.p_world;
  wanted.finger_count = frame.input.finger_count;
  for (int i = 0; i < frame.input.finger_count; ++i) {
    wanted.finger_force_n[static_cast<std::size_t>(i)] =
        std::sin(frame.input.finger_rad[static_cast<std::size_t>(i)]) * 10.0;
  }
  frame.command = watchdog.update(frame.input.time_s, &wanted, frame.input.healthy);
  if (frame.input.p_world.z() < 0.0) {
    frame.contact_count = 1;
    frame.contacts[0] = {0,
                         1,
                         2,
                         frame.input.p_world,
                         Vec3::UnitZ(),
                         -frame.input.p_world.z(),
                         frame.command.force_world_n.norm()};
  }
  device.write(frame.command);
  return frame;
}

TEST(Recording, ReplayReproducesTheSessionBitForBit) {
  const DeviceProfile& profile = device_profile("touch");
  SimulatedDevice live(
      profile,
      [](double t) {
        DeviceInput in;
        in.p_world = Vec3(0.01 * std::sin(7.0 * t), 0.003 * t, -0.004 * std::sin(3.0 * t));
        in.q_world = Quat(Eigen::AngleAxisd(t, Vec3::UnitY()));
        in.finger_count = 1;
        in.finger_rad[0] = t * t;
        in.healthy = !(t > 0.2 && t < 0.21);  // a short link drop
        return in;
      },
      0.5);
  const auto path = test::temp_path(".hrec");
  {
    ForceWatchdog watchdog(profile);
    SessionRecorder recorder(path, "toy-scene", 64, SessionRecorder::Overflow::kFlushInline);
    for (std::uint64_t c = 0; c < 500; ++c) {
      ASSERT_TRUE(recorder.record(step(live, c, watchdog)));
    }
    recorder.close();
  }
  const Recording original = read_recording(path);
  ASSERT_EQ(original.frames.size(), 500u);

  ReplayDevice replay(profile, original.frames);
  const auto path2 = test::temp_path("_replay.hrec");
  {
    ForceWatchdog watchdog(profile);
    SessionRecorder recorder(path2, "toy-scene", 64, SessionRecorder::Overflow::kFlushInline);
    for (std::uint64_t c = 0; c < 500; ++c) {
      ASSERT_TRUE(recorder.record(step(replay, c, watchdog)));
    }
    recorder.close();
  }
  EXPECT_TRUE(replay.finished());
  const Recording replayed = read_recording(path2);
  std::filesystem::remove(path);
  std::filesystem::remove(path2);

  const RecordingDifference d = compare_recordings(original, replayed);
  EXPECT_TRUE(d.identical) << d.message;
  // The commands the replayed step wrote are the recorded ones.
  ASSERT_EQ(replay.commands_written().size(), 500u);
  for (std::size_t i = 0; i < 500; ++i) {
    EXPECT_EQ(std::memcmp(replay.commands_written()[i].force_world_n.data(),
                          original.frames[i].command.force_world_n.data(), 3 * sizeof(double)),
              0)
        << i;
  }
  // The comparison is not vacuous: a one-ulp change in the replayed input is found.
  auto tampered = original.frames;
  tampered[321].input.p_world.x() = std::nextafter(tampered[321].input.p_world.x(), 1.0);
  ReplayDevice replay2(profile, tampered);
  ForceWatchdog watchdog(profile);
  std::vector<RecordedFrame> frames;
  for (std::uint64_t c = 0; c < 500; ++c) {
    frames.push_back(step(replay2, c, watchdog));
  }
  const RecordingDifference d2 = compare_frames(original.frames, frames);
  EXPECT_EQ(d2.frame_index, 321u);
  EXPECT_EQ(d2.field, "input.p_world[0]");
}

TEST(ReplayDevice, HoldsTheLastFrameAndReportsRecordedHealth) {
  auto frames = make_frames(3);
  frames[1].input.healthy = false;
  ReplayDevice device(device_profile("simulated"), frames);
  EXPECT_EQ(device.read(123.0).time_s, frames[0].input.time_s);  // the argument is ignored
  EXPECT_EQ(device.status().health, DeviceHealth::kConnected);
  EXPECT_FALSE(device.read(0.0).healthy);
  EXPECT_EQ(device.status().health, DeviceHealth::kFailed);
  EXPECT_FALSE(device.finished());
  EXPECT_EQ(device.read(0.0).time_s, frames[2].input.time_s);
  EXPECT_TRUE(device.finished());
  EXPECT_EQ(device.read(0.0).time_s, frames[2].input.time_s);
  device.rewind();
  EXPECT_EQ(device.next_frame(), 0u);
  EXPECT_EQ(device.read(0.0).time_s, frames[0].input.time_s);
  EXPECT_THROW(ReplayDevice(device_profile("simulated"), {}), Error);
}

}  // namespace
}  // namespace hapsim
