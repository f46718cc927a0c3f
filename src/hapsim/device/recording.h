// Session recording: every haptic cycle's device input, the command (the world's, clamped to the
// device: the deterministic part of the safety layer, not a real-time loop's wall-clock ramps) and
// the contacts, to a versioned binary file that replays bit-for-bit (docs/recording-format.md).
//
// Real-time trade-off: record() copies the frame into a vector reserved at construction, so it
// never allocates or touches the disk; flush() writes the buffered frames as one block (length and
// checksum: a reader keeps every whole block before a torn end) and is called off the haptic
// thread — by the real-time run's bookkeeping, which drains the haptic loop's record ring, as soon
// as flush_due() says (every kRecordingFlushFrames frames or 100 ms of device time), so a killed
// run loses at most the last 100 ms. When the buffer is full, record() either drops the frame and
// counts it (Overflow::kDrop, real-time) or flushes inline (Overflow::kFlushInline: blocking I/O,
// for offline and test runs where every frame must be kept).
#pragma once

#include "hapsim/device/device.h"

#include <array>
#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <limits>
#include <memory>
#include <span>
#include <string>
#include <vector>

namespace hapsim {

/// Contacts kept per cycle; more are counted by the world but not recorded.
inline constexpr int kMaxRecordedContacts = 16;
/// Version 3 writes frames in checksummed blocks (a torn end loses only the last block); version 2
/// added the scene file's path to the header. Versions 1 and 2 are still read.
inline constexpr std::uint32_t kRecordingVersion = 3;
/// Most frames in one block (bounds the reader's block buffer: 1024 frames are about 1.7 MB).
inline constexpr std::size_t kRecordingBlockMaxFrames = 1024;
/// flush_due() after this many buffered frames (100 ms at 1 kHz) or 100 ms of device time.
inline constexpr std::size_t kRecordingFlushFrames = 100;
inline constexpr double kRecordingFlushPeriodS = 0.1;
/// Longest scene hash string accepted in a header.
inline constexpr std::size_t kMaxSceneHashLength = 4096;
/// Longest scene path accepted in a header (version 2).
inline constexpr std::size_t kMaxScenePathLength = 4096;

/// One contact as the world reports it (plain data; indices are -1 when not applicable).
struct RecordedContact {
  std::int32_t tool_index = -1;
  std::int32_t body_index = -1;
  std::int32_t segment_index = -1;
  Vec3 point_world = Vec3::Zero();
  /// Unit contact normal, pointing out of the body towards the tool.
  Vec3 normal_world = Vec3::Zero();
  double depth_m = 0.0;
  double force_n = 0.0;
};

/// One haptic cycle. Unused array slots must be zero (DeviceInput/DeviceCommand default them) so
/// identical cycles give identical bytes.
struct RecordedFrame {
  std::uint64_t cycle_index = 0;
  DeviceInput input;
  /// The world's command clamped to the device's profile (to_recorded_frame, cycle_record.h).
  DeviceCommand command;
  std::int32_t contact_count = 0;
  std::array<RecordedContact, kMaxRecordedContacts> contacts{};
};

struct RecordingHeader {
  std::uint32_t version = kRecordingVersion;
  std::uint32_t frame_size_bytes = 0;
  /// Identifies the scene the session ran on (the world's content hash), so a replay against a
  /// different scene is noticed.
  std::string scene_hash;
  /// Version 2: the scene file as the command was given it and resolved to an absolute path
  /// (empty when the session was built in code, and in version 1 files), so `hapsim assess`
  /// finds the scene a recording was made on.
  std::string scene_path;
  std::string scene_path_absolute;
};

struct Recording {
  RecordingHeader header;
  std::vector<RecordedFrame> frames;
};

/// Bytes of one encoded frame in a version 1 or 2 file (marker + fields + checksum).
[[nodiscard]] std::size_t recorded_frame_size_bytes();
/// Bytes of one frame's fields: a version 3 block holds frames of this size back to back.
[[nodiscard]] std::size_t recorded_frame_payload_bytes();

class SessionRecorder {
 public:
  enum class Overflow { kDrop, kFlushInline };

  /// Creates `path` and writes the header. Throws hapsim::Error if the file cannot be created or
  /// the hash is longer than kMaxSceneHashLength. Reserves `capacity_frames` (> 0) frames.
  /// `scene_file`: the scene file the session runs (as given; its absolute path is added), if any.
  SessionRecorder(std::filesystem::path path, std::string scene_hash,
                  std::size_t capacity_frames = 4096, Overflow overflow = Overflow::kDrop,
                  const std::filesystem::path& scene_file = {});
  /// Flushes and closes; errors are swallowed here, call close() to see them.
  ~SessionRecorder();
  SessionRecorder(const SessionRecorder&) = delete;
  SessionRecorder& operator=(const SessionRecorder&) = delete;

  /// haptic path (with Overflow::kDrop): copies the frame into the buffer. Returns false when the
  /// frame was dropped (buffer full, or an inline flush failed: see last_error()).
  bool record(const RecordedFrame& frame) noexcept;

  /// Whether the buffer holds kRecordingFlushFrames frames or kRecordingFlushPeriodS of device
  /// time (or is full): the writer should flush() now to keep what a kill would lose small.
  [[nodiscard]] bool flush_due() const noexcept;
  /// Not on the haptic path: writes the buffered frames as blocks of at most
  /// kRecordingBlockMaxFrames and hands them to the kernel (a killed process keeps them; no
  /// fsync). Throws hapsim::Error on a write error (also one remembered from an inline flush); the
  /// file then keeps the header and every whole block that reached the disk (a partial one is cut
  /// off), and the recorder is closed.
  void flush();
  /// Flushes and closes the file; further record() calls drop.
  void close();

  [[nodiscard]] const std::filesystem::path& path() const { return path_; }
  [[nodiscard]] std::size_t frames_written() const { return frames_written_; }
  [[nodiscard]] std::size_t frames_buffered() const { return buffer_.size(); }
  [[nodiscard]] std::size_t capacity_frames() const { return capacity_frames_; }
  [[nodiscard]] std::size_t frames_dropped() const { return frames_dropped_; }
  [[nodiscard]] const std::string& last_error() const { return last_error_; }

 private:
  void write_buffer();
  /// After a failed write: closes the file, cut back to the header and the whole blocks written
  /// before (frames_written() says how many frames), and drops the rest of the buffer.
  void keep_complete_blocks() noexcept;

  std::filesystem::path path_;
  std::ofstream out_;
  std::vector<RecordedFrame> buffer_;
  std::vector<unsigned char> bytes_;  // one encoded block, reserved for the largest
  std::size_t capacity_frames_ = 0;
  std::uintmax_t bytes_written_ = 0;  // header and whole blocks on disk
  Overflow overflow_ = Overflow::kDrop;
  std::size_t frames_written_ = 0;
  std::size_t frames_dropped_ = 0;
  std::string last_error_;
  bool closed_ = false;
};

/// Streams frames from a recording file, validating the header on open and every frame as it is
/// read; memory is one block whatever the file's length. Errors are hapsim::Error naming the file
/// and the frame index; never a crash. A torn end (the file stops inside a block or a version 1/2
/// frame: the writer was killed or the disk filled) is not an error: next() returns false after
/// the last whole frame and, with TornEnd::kWarn, says once on stderr how many frames it kept.
/// A complete block or frame that fails its checks is corruption, and an error.
class RecordingReader {
 public:
  enum class TornEnd : std::uint8_t { kWarn, kQuiet };

  explicit RecordingReader(std::filesystem::path path, TornEnd torn_end = TornEnd::kWarn);

  [[nodiscard]] const RecordingHeader& header() const { return header_; }
  /// About the number of frames the file size implies (exact for versions 1 and 2).
  [[nodiscard]] std::size_t frame_count_hint() const { return frame_count_hint_; }
  /// Reads the next frame into `frame`; false at the end of the file (clean or torn).
  bool next(RecordedFrame& frame);
  /// Index of the frame the next call to next() reads.
  [[nodiscard]] std::size_t frame_index() const { return frame_index_; }
  /// Bytes after the last whole frame that next() left (0 for a clean end, or before the end).
  [[nodiscard]] std::uintmax_t torn_bytes() const { return torn_bytes_; }

 private:
  /// Reads the next version 3 block into bytes_; false at the end (clean or torn).
  bool read_block();
  void note_torn_end(std::uintmax_t bytes_left);

  std::filesystem::path path_;
  std::ifstream in_;
  TornEnd torn_end_ = TornEnd::kWarn;
  RecordingHeader header_;
  std::uintmax_t file_size_ = 0;
  std::uintmax_t offset_ = 0;  // of the next unread frame (v1/2) or block (v3)
  std::size_t frame_count_hint_ = 0;
  std::size_t frame_index_ = 0;
  std::uintmax_t torn_bytes_ = 0;
  std::vector<unsigned char> bytes_;  // one frame (v1/2) or one block (v3)
  std::size_t block_frames_ = 0;      // frames in the block in bytes_ (v3)
  std::size_t block_next_ = 0;        // the next of them next() returns
};

/// Reads a whole recording (RecordingReader until the end; a torn end is warned about once).
[[nodiscard]] Recording read_recording(const std::filesystem::path& path);

/// What a first pass over a recording found (every frame read and checked, none kept).
struct RecordingScan {
  RecordingHeader header;
  std::size_t frames = 0;
  RecordedFrame first_frame;  // meaningful when frames > 0
  std::uintmax_t torn_bytes = 0;
};
/// Reads `path` frame by frame in constant memory, checking every frame (errors as
/// RecordingReader's; a torn end is warned about once).
[[nodiscard]] RecordingScan scan_recording(const std::filesystem::path& path);

/// Plays recorded inputs back cycle by cycle: each read() returns the next frame's input exactly
/// as recorded (time_s included; the time argument is ignored, so call read() once per cycle as
/// World::step does). After the last frame it holds that input and reports finished().
/// From memory (a vector of frames): commands written are kept (no allocation up to one per
/// frame) to compare with the recording. Streamed from a file: a reader thread keeps up to
/// kReplayPrefetchFrames frames ahead in a lock-free ring, so memory does not grow with the
/// file's length and read() touches no disk (it waits only if the disk falls that far behind);
/// no commands are kept.
class ReplayDevice final : public Device {
 public:
  static constexpr std::size_t kReplayPrefetchFrames = 2048;

  ReplayDevice(DeviceProfile profile, std::vector<RecordedFrame> frames);
  /// Streams the first `frame_count` (> 0) frames of `recording`, which scan_recording() has
  /// checked. Should the file change meanwhile and fail to read, the device reports kFailed with
  /// the reader's error and holds its last input.
  ReplayDevice(DeviceProfile profile, std::filesystem::path recording, std::size_t frame_count);
  ~ReplayDevice() override;
  ReplayDevice(const ReplayDevice&) = delete;
  ReplayDevice& operator=(const ReplayDevice&) = delete;

  [[nodiscard]] DeviceInput read(double time_s) noexcept override;
  void write(const DeviceCommand& command) noexcept override;
  [[nodiscard]] const DeviceProfile& profile() const noexcept override { return profile_; }
  [[nodiscard]] DeviceStatus status() const noexcept override;

  [[nodiscard]] bool finished() const noexcept { return next_frame_ >= frame_count_; }
  /// Index of the frame the next read() returns.
  [[nodiscard]] std::size_t next_frame() const noexcept { return next_frame_; }
  [[nodiscard]] std::size_t frame_count() const noexcept { return frame_count_; }
  /// Not on the haptic path (a streamed replay restarts its reader).
  void rewind();
  /// The frames of an in-memory replay (empty when streamed).
  [[nodiscard]] const std::vector<RecordedFrame>& frames() const noexcept { return frames_; }
  [[nodiscard]] const std::vector<DeviceCommand>& commands_written() const noexcept {
    return commands_;
  }

 private:
  struct Stream;
  void start_stream();
  void stop_stream() noexcept;

  DeviceProfile profile_;
  std::vector<RecordedFrame> frames_;
  std::size_t frame_count_ = 0;
  std::size_t next_frame_ = 0;
  DeviceInput last_input_;
  bool last_healthy_ = true;
  std::vector<DeviceCommand> commands_;
  std::filesystem::path path_;      // streamed replays
  std::unique_ptr<Stream> stream_;  // streamed replays: the reader thread and its ring
};

/// Where two recordings first differ. Doubles are compared bit for bit (so -0 != +0 and a NaN
/// equals the same NaN): "equal" means a replay reproduced the session exactly.
struct RecordingDifference {
  bool identical = true;
  /// Frame of the first difference; kNoFrame for a header or frame-count difference.
  std::size_t frame_index = kNoFrame;
  /// E.g. "command.finger_force_n[2]", "contacts[1].point_world[0]", "header.scene_hash".
  std::string field;
  std::string expected_value;
  std::string actual_value;
  /// One line for people: "frame 12, command.force_world_n[0]: expected 0.5, got 0.50000000001".
  std::string message;

  static constexpr std::size_t kNoFrame = std::numeric_limits<std::size_t>::max();
};

[[nodiscard]] RecordingDifference compare_frames(std::span<const RecordedFrame> expected,
                                                 std::span<const RecordedFrame> actual);
[[nodiscard]] RecordingDifference compare_recordings(const Recording& expected,
                                                     const Recording& actual);
/// compare_recordings() of two files, frame by frame in constant memory (no torn-end warnings:
/// whoever read the files before has said so).
[[nodiscard]] RecordingDifference compare_recording_files(const std::filesystem::path& expected,
                                                          const std::filesystem::path& actual);

}  // namespace hapsim
