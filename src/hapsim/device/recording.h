// Session recording: every haptic cycle's device input, the command (the world's, clamped to the
// device: the deterministic part of the safety layer, not a real-time loop's wall-clock ramps) and
// the contacts, to a versioned binary file that replays bit-for-bit (docs/recording-format.md).
//
// Real-time trade-off (this issue): record() copies the frame into a vector reserved at
// construction, so the haptic path never allocates or touches the disk; flush() encodes and
// writes the buffered frames and must be called from outside the haptic path (the graphics loop,
// or every N cycles in an offline run). When the buffer is full, record() either drops the frame
// and counts it (Overflow::kDrop, real-time) or flushes inline (Overflow::kFlushInline: blocking
// I/O, for offline and test runs where every frame must be kept). A lock-free single-producer
// ring drained by a writer thread replaces this in the real-time issue; the file format stays.
#pragma once

#include "hapsim/device/device.h"

#include <array>
#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <limits>
#include <span>
#include <string>
#include <vector>

namespace hapsim {

/// Contacts kept per cycle; more are counted by the world but not recorded.
inline constexpr int kMaxRecordedContacts = 16;
/// Version 2 adds the scene file's path to the header (version 1 files are still read).
inline constexpr std::uint32_t kRecordingVersion = 2;
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

/// Bytes of one encoded frame on disk (marker + fields + checksum), for version 1.
[[nodiscard]] std::size_t recorded_frame_size_bytes();

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

  /// Not on the haptic path: writes the buffered frames. Throws hapsim::Error on a write error
  /// (also one remembered from an inline flush); the file then keeps the header and every whole
  /// frame that reached the disk (a partial one is cut off), and the recorder is closed.
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
  /// After a failed write: closes the file, cut back to the header and the whole frames on disk
  /// (frames_written() says how many), and drops the rest of the buffer.
  void keep_complete_frames() noexcept;

  std::filesystem::path path_;
  std::ofstream out_;
  std::vector<RecordedFrame> buffer_;
  std::vector<unsigned char> bytes_;  // one encoded frame, reused
  std::size_t capacity_frames_ = 0;
  std::size_t header_bytes_ = 0;
  Overflow overflow_ = Overflow::kDrop;
  std::size_t frames_written_ = 0;
  std::size_t frames_dropped_ = 0;
  std::string last_error_;
  bool closed_ = false;
};

/// Streams frames from a recording file, validating the header on open and every frame as it is
/// read. Errors are hapsim::Error naming the file and the frame index; never a crash.
class RecordingReader {
 public:
  explicit RecordingReader(std::filesystem::path path);

  [[nodiscard]] const RecordingHeader& header() const { return header_; }
  /// Number of complete frames the file size implies (a truncated tail is reported by next()).
  [[nodiscard]] std::size_t frame_count_hint() const { return frame_count_hint_; }
  /// Reads the next frame into `frame`; false at a clean end of file.
  bool next(RecordedFrame& frame);
  /// Index of the frame the next call to next() reads.
  [[nodiscard]] std::size_t frame_index() const { return frame_index_; }

 private:
  std::filesystem::path path_;
  std::ifstream in_;
  RecordingHeader header_;
  std::uintmax_t file_size_ = 0;
  std::uintmax_t offset_ = 0;
  std::size_t frame_count_hint_ = 0;
  std::size_t frame_index_ = 0;
  std::vector<unsigned char> bytes_;
};

/// Reads a whole recording (RecordingReader until the end).
[[nodiscard]] Recording read_recording(const std::filesystem::path& path);

/// Plays recorded inputs back cycle by cycle: each read() returns the next frame's input exactly
/// as recorded (time_s included; the time argument is ignored, so call read() once per cycle as
/// World::step does). After the last frame it holds that input and reports finished().
/// Commands written are kept (no allocation up to one per frame) to compare with the recording.
class ReplayDevice final : public Device {
 public:
  ReplayDevice(DeviceProfile profile, std::vector<RecordedFrame> frames);

  [[nodiscard]] DeviceInput read(double time_s) noexcept override;
  void write(const DeviceCommand& command) noexcept override;
  [[nodiscard]] const DeviceProfile& profile() const noexcept override { return profile_; }
  [[nodiscard]] DeviceStatus status() const noexcept override;

  [[nodiscard]] bool finished() const noexcept { return next_frame_ >= frames_.size(); }
  /// Index of the frame the next read() returns.
  [[nodiscard]] std::size_t next_frame() const noexcept { return next_frame_; }
  void rewind() noexcept;
  [[nodiscard]] const std::vector<RecordedFrame>& frames() const noexcept { return frames_; }
  [[nodiscard]] const std::vector<DeviceCommand>& commands_written() const noexcept {
    return commands_;
  }

 private:
  DeviceProfile profile_;
  std::vector<RecordedFrame> frames_;
  std::size_t next_frame_ = 0;
  bool last_healthy_ = true;
  std::vector<DeviceCommand> commands_;
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

}  // namespace hapsim
