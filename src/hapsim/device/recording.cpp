#include "hapsim/device/recording.h"

#include "hapsim/core/error.h"
#include "hapsim/core/printable_text.h"
#include "hapsim/core/spsc_ring.h"

#include <algorithm>
#include <atomic>
#include <bit>
#include <charconv>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <thread>
#include <type_traits>
#include <utility>

namespace hapsim {
namespace {

static_assert(std::endian::native == std::endian::little,
              "recordings are little-endian and written with memcpy; add byte swapping to port");

constexpr std::array<char, 8> kMagic = {'H', 'A', 'P', 'S', 'I', 'M', 'R', 'C'};
constexpr std::uint32_t kFrameMarker = 0x31524648u;  // "HFR1" in file byte order (v1, v2)
constexpr std::uint32_t kBlockMarker = 0x334b4248u;  // "HBK3" in file byte order (v3)
// Block: marker, frame count, payload length (u32 each), the frames' fields, FNV-1a 64 of all that.
constexpr std::size_t kBlockHeadBytes = 3 * 4;
constexpr std::size_t kBlockChecksumBytes = 8;
// magic + version + frame size + max contacts + max fingers + max joints + hash length
constexpr std::size_t kHeaderFixedBytes = 8 + 6 * 4;

// Names one field for comparison messages: group[group_index].name[index].
struct FieldId {
  const char* group;  // nullptr for top-level fields
  int group_index;    // -1 when the group is not an array
  const char* name;
  int index;  // -1 for a scalar
};

std::string field_name(const FieldId& id) {
  std::string s;
  if (id.group != nullptr) {
    s += id.group;
    if (id.group_index >= 0) {
      s += "[" + std::to_string(id.group_index) + "]";
    }
    s += ".";
  }
  s += id.name;
  if (id.index >= 0) {
    s += "[" + std::to_string(id.index) + "]";
  }
  return s;
}

// The one list of a frame's fields, in file order. Encoding, decoding, sizing and comparison all
// walk it, so they cannot disagree about the layout.
template <class Frame, class Visitor>
void visit_frame(Frame& f, Visitor& v) {
  v(FieldId{nullptr, -1, "cycle_index", -1}, f.cycle_index);
  auto& in = f.input;
  v(FieldId{"input", -1, "time_s", -1}, in.time_s);
  for (int k = 0; k < 3; ++k) {
    v(FieldId{"input", -1, "p_world", k}, in.p_world[k]);
  }
  // Eigen stores (x, y, z, w); written in that order.
  for (int k = 0; k < 4; ++k) {
    v(FieldId{"input", -1, "q_world.coeffs(xyzw)", k}, in.q_world.coeffs()[k]);
  }
  for (int k = 0; k < kMaxDeviceJoints; ++k) {
    v(FieldId{"input", -1, "joint_rad", k}, in.joint_rad[static_cast<std::size_t>(k)]);
  }
  v(FieldId{"input", -1, "joint_count", -1}, in.joint_count);
  for (int k = 0; k < kMaxFingers; ++k) {
    v(FieldId{"input", -1, "finger_rad", k}, in.finger_rad[static_cast<std::size_t>(k)]);
  }
  v(FieldId{"input", -1, "finger_count", -1}, in.finger_count);
  v(FieldId{"input", -1, "buttons", -1}, in.buttons);
  v(FieldId{"input", -1, "healthy", -1}, in.healthy);

  auto& cmd = f.command;
  for (int k = 0; k < 3; ++k) {
    v(FieldId{"command", -1, "force_world_n", k}, cmd.force_world_n[k]);
  }
  for (int k = 0; k < kMaxFingers; ++k) {
    v(FieldId{"command", -1, "finger_force_n", k}, cmd.finger_force_n[static_cast<std::size_t>(k)]);
  }
  v(FieldId{"command", -1, "finger_count", -1}, cmd.finger_count);
  for (int k = 0; k < kMaxDeviceJoints; ++k) {
    v(FieldId{"command", -1, "joint_torque_nm", k},
      cmd.joint_torque_nm[static_cast<std::size_t>(k)]);
  }
  v(FieldId{"command", -1, "joint_count", -1}, cmd.joint_count);

  v(FieldId{nullptr, -1, "contact_count", -1}, f.contact_count);
  for (int c = 0; c < kMaxRecordedContacts; ++c) {
    auto& contact = f.contacts[static_cast<std::size_t>(c)];
    v(FieldId{"contacts", c, "tool_index", -1}, contact.tool_index);
    v(FieldId{"contacts", c, "body_index", -1}, contact.body_index);
    v(FieldId{"contacts", c, "segment_index", -1}, contact.segment_index);
    for (int k = 0; k < 3; ++k) {
      v(FieldId{"contacts", c, "point_world", k}, contact.point_world[k]);
    }
    for (int k = 0; k < 3; ++k) {
      v(FieldId{"contacts", c, "normal_world", k}, contact.normal_world[k]);
    }
    v(FieldId{"contacts", c, "depth_m", -1}, contact.depth_m);
    v(FieldId{"contacts", c, "force_n", -1}, contact.force_n);
  }
}

template <class T>
constexpr std::size_t encoded_size() {
  return std::is_same_v<T, bool> ? 1 : sizeof(T);
}

struct Sizer {
  std::size_t bytes = 0;
  template <class T>
  void operator()(const FieldId&, const T&) {
    bytes += encoded_size<std::remove_cvref_t<T>>();
  }
};

struct Encoder {
  unsigned char* p;
  template <class T>
  void operator()(const FieldId&, const T& value) {
    if constexpr (std::is_same_v<T, bool>) {
      *p++ = value ? 1 : 0;
    } else {
      std::memcpy(p, &value, sizeof(T));  // bit-exact, doubles included
      p += sizeof(T);
    }
  }
};

struct Decoder {
  const unsigned char* p;
  bool bad_bool = false;
  template <class T>
  void operator()(const FieldId&, T& value) {
    if constexpr (std::is_same_v<T, bool>) {
      bad_bool = bad_bool || *p > 1;
      value = *p++ != 0;
    } else {
      std::memcpy(&value, p, sizeof(T));
      p += sizeof(T);
    }
  }
};

// FNV-1a, 64 bit: detects corrupted frames; not cryptographic (nobody forges recordings).
std::uint64_t fnv1a(const unsigned char* data, std::size_t size) {
  std::uint64_t h = 0xcbf29ce484222325ull;
  for (std::size_t i = 0; i < size; ++i) {
    h ^= data[i];
    h *= 0x100000001b3ull;
  }
  return h;
}

std::size_t payload_size() {
  static const std::size_t size = [] {
    Sizer sizer;
    const RecordedFrame frame;
    visit_frame(frame, sizer);
    return sizer.bytes;
  }();
  return size;
}

// Encodes the frame's fields into `out` (payload_size() long).
void encode_payload(const RecordedFrame& frame, unsigned char* out) {
  Encoder encoder{out};
  visit_frame(frame, encoder);
}

// Encodes marker + payload + checksum into `out` (recorded_frame_size_bytes() long): a version 1
// or 2 frame, and the unit the comparison compares.
void encode_frame(const RecordedFrame& frame, unsigned char* out) {
  std::memcpy(out, &kFrameMarker, 4);
  encode_payload(frame, out + 4);
  const std::uint64_t sum = fnv1a(out + 4, payload_size());
  std::memcpy(out + 4 + payload_size(), &sum, 8);
}

template <class T>
void put(std::vector<unsigned char>& out, const T& value) {
  const auto* bytes = reinterpret_cast<const unsigned char*>(&value);
  out.insert(out.end(), bytes, bytes + sizeof(T));
}

template <class T>
T get(const unsigned char* p) {
  T value;
  std::memcpy(&value, p, sizeof(T));
  return value;
}

std::string format_value(double v) {
  std::array<char, 32> buf{};
  const auto [ptr, ec] = std::to_chars(buf.data(), buf.data() + buf.size(), v);
  (void)ec;
  return std::string(buf.data(), ptr);
}

template <class T>
std::string format_value(const T& v) {
  if constexpr (std::is_same_v<T, bool>) {
    return v ? "true" : "false";
  } else {
    return std::to_string(v);
  }
}

// Collects (field, bytes, text) of a frame for a field-by-field comparison (offline only).
struct Flattener {
  struct Entry {
    FieldId id;
    std::array<unsigned char, 8> bytes{};
    std::string text;
  };
  std::vector<Entry> entries;
  template <class T>
  void operator()(const FieldId& id, const T& value) {
    Entry e{id, {}, format_value(value)};
    if constexpr (std::is_same_v<T, bool>) {
      e.bytes[0] = value ? 1 : 0;
    } else {
      std::memcpy(e.bytes.data(), &value, sizeof(T));
    }
    entries.push_back(std::move(e));
  }
};

const char* check_counts(const RecordedFrame& f) {
  if (f.input.finger_count < 0 || f.input.finger_count > kMaxFingers) {
    return "input.finger_count out of range";
  }
  if (f.input.joint_count < 0 || f.input.joint_count > kMaxDeviceJoints) {
    return "input.joint_count out of range";
  }
  if (f.command.finger_count < 0 || f.command.finger_count > kMaxFingers) {
    return "command.finger_count out of range";
  }
  if (f.command.joint_count < 0 || f.command.joint_count > kMaxDeviceJoints) {
    return "command.joint_count out of range";
  }
  if (f.contact_count < 0 || f.contact_count > kMaxRecordedContacts) {
    return "contact_count out of range";
  }
  return nullptr;
}

// The first input or command number that is not finite: a device's input is checked before it is
// recorded (a plugin's NaN sample is refused) and the command is the world's, NaN already zeroed,
// so a recording holding one is corrupt or made up, and a replay of it proves nothing.
struct NonFiniteFinder {
  std::string field;
  template <class T>
  void operator()(const FieldId& id, const T& value) {
    if constexpr (std::is_floating_point_v<T>) {
      if (field.empty() && id.group != nullptr && id.group_index < 0 && !std::isfinite(value)) {
        field = field_name(id) + " is " + format_value(value);
      }
    }
  }
};

// Decodes one frame's fields and checks them; the problem, or "" when the frame is sound.
std::string decode_checked(const unsigned char* payload, RecordedFrame& frame) {
  RecordedFrame decoded;
  Decoder decoder{payload};
  visit_frame(decoded, decoder);
  if (decoder.bad_bool) {
    return "input.healthy is neither 0 nor 1";
  }
  if (const char* problem = check_counts(decoded)) {
    return problem;
  }
  NonFiniteFinder non_finite;
  visit_frame(decoded, non_finite);
  if (!non_finite.field.empty()) {
    return non_finite.field + "; a recording holds finite inputs and commands only";
  }
  frame = decoded;
  return {};
}

}  // namespace

std::size_t recorded_frame_size_bytes() {
  return 4 + payload_size() + 8;
}

std::size_t recorded_frame_payload_bytes() {
  return payload_size();
}

// ---------------------------------------------------------------------------------------------
// SessionRecorder

SessionRecorder::SessionRecorder(std::filesystem::path path, std::string scene_hash,
                                 std::size_t capacity_frames, Overflow overflow,
                                 const std::filesystem::path& scene_file)
    : path_(std::move(path)), capacity_frames_(capacity_frames), overflow_(overflow) {
  const std::string where = path_.string();
  if (capacity_frames_ == 0) {
    throw Error(where, "recorder buffer capacity must be at least one frame");
  }
  if (scene_hash.size() > kMaxSceneHashLength) {
    throw Error(where, "scene hash is " + std::to_string(scene_hash.size()) +
                           " characters, at most " + std::to_string(kMaxSceneHashLength) +
                           " allowed");
  }
  std::string scene_path;
  std::string scene_path_absolute;
  if (!scene_file.empty()) {
    std::error_code ec;
    scene_path = scene_file.string();
    const std::filesystem::path absolute = std::filesystem::absolute(scene_file, ec);
    scene_path_absolute = std::filesystem::weakly_canonical(absolute, ec).string();
    if (ec) {
      scene_path_absolute = absolute.string();
    }
  }
  if (scene_path.size() > kMaxScenePathLength || scene_path_absolute.size() > kMaxScenePathLength) {
    throw Error(where, "the scene's path is longer than " + std::to_string(kMaxScenePathLength) +
                           " characters");
  }
  out_.open(path_, std::ios::binary | std::ios::trunc);
  if (!out_) {
    throw Error(where, "cannot create recording file");
  }
  std::vector<unsigned char> header(kMagic.begin(), kMagic.end());
  put(header, kRecordingVersion);
  put(header, static_cast<std::uint32_t>(payload_size()));
  put(header, static_cast<std::uint32_t>(kMaxRecordedContacts));
  put(header, static_cast<std::uint32_t>(kMaxFingers));
  put(header, static_cast<std::uint32_t>(kMaxDeviceJoints));
  put(header, static_cast<std::uint32_t>(scene_hash.size()));
  header.insert(header.end(), scene_hash.begin(), scene_hash.end());
  for (const std::string* text : {&scene_path, &scene_path_absolute}) {
    put(header, static_cast<std::uint32_t>(text->size()));
    header.insert(header.end(), text->begin(), text->end());
  }
  put(header, fnv1a(header.data(), header.size()));
  out_.write(reinterpret_cast<const char*>(header.data()),
             static_cast<std::streamsize>(header.size()));
  out_.flush();
  if (!out_) {
    throw Error(where, "cannot write recording header");
  }
  bytes_written_ = header.size();
  buffer_.reserve(capacity_frames_);
  bytes_.resize(kBlockHeadBytes +
                std::min(capacity_frames_, kRecordingBlockMaxFrames) * payload_size() +
                kBlockChecksumBytes);
}

SessionRecorder::~SessionRecorder() {
  try {
    close();
  } catch (...) {  // NOLINT(bugprone-empty-catch): documented, close() reports errors
  }
}

bool SessionRecorder::record(const RecordedFrame& frame) noexcept {
  if (closed_ || check_counts(frame) != nullptr) {
    ++frames_dropped_;
    return false;
  }
  if (buffer_.size() == capacity_frames_) {
    if (overflow_ == Overflow::kDrop) {
      ++frames_dropped_;
      return false;
    }
    try {
      write_buffer();
    } catch (const std::exception& e) {
      try {
        last_error_ = e.what();
      } catch (...) {  // out of memory for the message: the drop count still tells
      }
      ++frames_dropped_;
      return false;
    }
  }
  buffer_.push_back(frame);  // within the reserved capacity: no allocation
  return true;
}

bool SessionRecorder::flush_due() const noexcept {
  if (buffer_.empty()) {
    return false;
  }
  return buffer_.size() >= std::min(capacity_frames_, kRecordingFlushFrames) ||
         buffer_.back().input.time_s - buffer_.front().input.time_s >= kRecordingFlushPeriodS;
}

void SessionRecorder::write_buffer() {
  const std::size_t payload = payload_size();
  for (std::size_t first = 0; first < buffer_.size(); first += kRecordingBlockMaxFrames) {
    const std::size_t count = std::min(kRecordingBlockMaxFrames, buffer_.size() - first);
    const auto length = static_cast<std::uint32_t>(count * payload);
    unsigned char* p = bytes_.data();
    std::memcpy(p, &kBlockMarker, 4);
    const auto count32 = static_cast<std::uint32_t>(count);
    std::memcpy(p + 4, &count32, 4);
    std::memcpy(p + 8, &length, 4);
    for (std::size_t i = 0; i < count; ++i) {
      encode_payload(buffer_[first + i], p + kBlockHeadBytes + i * payload);
    }
    const std::size_t checked = kBlockHeadBytes + length;
    const std::uint64_t sum = fnv1a(p, checked);
    std::memcpy(p + checked, &sum, 8);
    // One block, one write handed to the kernel: a killed process leaves whole blocks and at
    // most one torn one, which the reader drops.
    out_.write(reinterpret_cast<const char*>(p), static_cast<std::streamsize>(checked + 8));
    out_.flush();
    if (!out_) {
      keep_complete_blocks();
      throw Error(path_.string(), "write failed (disk full?): the recording keeps its first " +
                                      std::to_string(frames_written_) +
                                      " frame(s), readable and replayable; later ones are lost");
    }
    bytes_written_ += checked + 8;
    frames_written_ += count;
  }
  buffer_.clear();  // keeps the capacity
}

void SessionRecorder::keep_complete_blocks() noexcept {
  // A full disk takes what fits: whole blocks and maybe part of one. Cut the part (the reader
  // would drop it as a torn end and warn) so the file ends cleanly after the last whole block.
  closed_ = true;
  out_.close();
  std::error_code ec;
  std::filesystem::resize_file(path_, bytes_written_, ec);
  buffer_.clear();
}

void SessionRecorder::flush() {
  if (!last_error_.empty()) {
    throw Error(path_.string(), last_error_);
  }
  if (!closed_) {
    write_buffer();
  }
}

void SessionRecorder::close() {
  if (closed_) {
    return;
  }
  flush();
  closed_ = true;
  out_.close();
  if (out_.fail()) {
    throw Error(path_.string(), "closing the recording failed");
  }
}

// ---------------------------------------------------------------------------------------------
// RecordingReader

RecordingReader::RecordingReader(std::filesystem::path path, TornEnd torn_end)
    : path_(std::move(path)), torn_end_(torn_end) {
  const std::string where = path_.string();
  std::error_code ec;
  // Not a FIFO, a device or a folder: opening a FIFO blocks until something writes to it (assess
  // hung forever), and only a regular file has a size to check frames against.
  const auto status = std::filesystem::status(path_, ec);
  if (!ec && std::filesystem::exists(status) && !std::filesystem::is_regular_file(status)) {
    throw Error(where,
                "cannot open recording file: not a regular file (a pipe, a device or a "
                "folder); a recording is a file hapsim run --record wrote");
  }
  file_size_ = std::filesystem::file_size(path_, ec);
  in_.open(path_, std::ios::binary);
  if (ec || !in_) {
    throw Error(where, "cannot open recording file");
  }
  std::vector<unsigned char> head(kHeaderFixedBytes);
  in_.read(reinterpret_cast<char*>(head.data()), static_cast<std::streamsize>(head.size()));
  if (static_cast<std::size_t>(in_.gcount()) != head.size()) {
    throw Error(where, "not a hapsim recording: " + std::to_string(file_size_) +
                           " bytes, too short for the header");
  }
  if (!std::equal(kMagic.begin(), kMagic.end(), head.begin())) {
    throw Error(where, "not a hapsim recording: bad magic (expected 'HAPSIMRC')");
  }
  header_.version = get<std::uint32_t>(&head[8]);
  header_.frame_size_bytes = get<std::uint32_t>(&head[12]);
  const auto max_contacts = get<std::uint32_t>(&head[16]);
  const auto max_fingers = get<std::uint32_t>(&head[20]);
  const auto max_joints = get<std::uint32_t>(&head[24]);
  const auto hash_length = get<std::uint32_t>(&head[28]);
  if (header_.version < 1 || header_.version > kRecordingVersion) {
    throw Error(where, "recording version " + std::to_string(header_.version) +
                           ", this build reads versions 1 to " + std::to_string(kRecordingVersion));
  }
  // Versions 1 and 2: each frame has its marker and checksum; version 3: the fields only.
  const std::size_t frame_bytes =
      header_.version >= 3 ? payload_size() : recorded_frame_size_bytes();
  if (header_.frame_size_bytes != frame_bytes ||
      max_contacts != static_cast<std::uint32_t>(kMaxRecordedContacts) ||
      max_fingers != static_cast<std::uint32_t>(kMaxFingers) ||
      max_joints != static_cast<std::uint32_t>(kMaxDeviceJoints)) {
    throw Error(where, "corrupt header: frame size " + std::to_string(header_.frame_size_bytes) +
                           " bytes, " + std::to_string(max_contacts) + " contacts, " +
                           std::to_string(max_fingers) + " fingers, " + std::to_string(max_joints) +
                           " joints; this build expects " + std::to_string(frame_bytes) + ", " +
                           std::to_string(kMaxRecordedContacts) + ", " +
                           std::to_string(kMaxFingers) + ", " + std::to_string(kMaxDeviceJoints));
  }
  if (hash_length > kMaxSceneHashLength || kHeaderFixedBytes + hash_length + 8 > file_size_) {
    throw Error(where, "corrupt header: scene hash length " + std::to_string(hash_length) +
                           " (at most " + std::to_string(kMaxSceneHashLength) +
                           " and within the file expected)");
  }
  // Reads `n` more header bytes onto `head`.
  const auto read_more = [&](std::size_t n) {
    if (head.size() + n > file_size_) {
      throw Error(where, "truncated header");
    }
    const std::size_t at = head.size();
    head.resize(at + n);
    in_.read(reinterpret_cast<char*>(head.data() + at), static_cast<std::streamsize>(n));
    if (static_cast<std::size_t>(in_.gcount()) != n) {
      throw Error(where, "truncated header");
    }
  };
  read_more(hash_length);
  header_.scene_hash.assign(reinterpret_cast<const char*>(&head[kHeaderFixedBytes]), hash_length);
  if (header_.version >= 2) {
    for (std::string* text : {&header_.scene_path, &header_.scene_path_absolute}) {
      read_more(4);
      const auto length = get<std::uint32_t>(&head[head.size() - 4]);
      if (length > kMaxScenePathLength) {
        throw Error(where, "corrupt header: scene path length " + std::to_string(length) +
                               " (at most " + std::to_string(kMaxScenePathLength) + ")");
      }
      read_more(length);
      text->assign(reinterpret_cast<const char*>(&head[head.size() - length]), length);
    }
  }
  const std::size_t checked = head.size();
  read_more(8);
  if (get<std::uint64_t>(&head[checked]) != fnv1a(head.data(), checked)) {
    throw Error(where, "corrupt header: checksum mismatch");
  }
  offset_ = head.size();
  frame_count_hint_ = static_cast<std::size_t>((file_size_ - offset_) / header_.frame_size_bytes);
  if (header_.version < 3) {
    bytes_.resize(header_.frame_size_bytes);
  }
}

void RecordingReader::note_torn_end(std::uintmax_t bytes_left) {
  torn_bytes_ = bytes_left;
  offset_ = file_size_;
  if (torn_end_ == TornEnd::kWarn) {
    // Once per reader: it reads no further. The file name is data: printed escaped.
    std::fprintf(stderr,
                 "warning: %s: the recording ends in %ju byte(s) that are not a whole %s (the "
                 "session was interrupted while writing); kept the %zu whole frame(s) before\n",
                 printable_text(path_.string(), 4096).c_str(), bytes_left,
                 header_.version >= 3 ? "block" : "frame", frame_index_);
  }
}

bool RecordingReader::read_block() {
  const std::string where = path_.string();
  const std::uintmax_t left = file_size_ - offset_;
  const std::string which = "block at byte offset " + std::to_string(offset_) + " (frame " +
                            std::to_string(frame_index_) + " on)";
  if (left < kBlockHeadBytes) {
    note_torn_end(left);
    return false;
  }
  std::array<unsigned char, kBlockHeadBytes> head{};
  in_.read(reinterpret_cast<char*>(head.data()), static_cast<std::streamsize>(head.size()));
  if (static_cast<std::size_t>(in_.gcount()) != head.size()) {
    throw Error(where, which + ": read failed");
  }
  const auto count = get<std::uint32_t>(&head[4]);
  const auto length = get<std::uint32_t>(&head[8]);
  if (get<std::uint32_t>(head.data()) != kBlockMarker) {
    throw Error(where, which + " is corrupt: bad block marker");
  }
  if (count == 0 || count > kRecordingBlockMaxFrames ||
      length != static_cast<std::uint64_t>(count) * payload_size()) {
    throw Error(where, which + " is corrupt: " + std::to_string(count) + " frame(s) in " +
                           std::to_string(length) + " bytes (1 to " +
                           std::to_string(kRecordingBlockMaxFrames) + " frames of " +
                           std::to_string(payload_size()) + " bytes expected)");
  }
  const std::uintmax_t block_bytes = kBlockHeadBytes + length + kBlockChecksumBytes;
  if (block_bytes > left) {
    note_torn_end(left);
    return false;
  }
  bytes_.resize(kBlockHeadBytes + length + kBlockChecksumBytes);  // at most one largest block
  std::memcpy(bytes_.data(), head.data(), head.size());
  const std::size_t rest = length + kBlockChecksumBytes;
  in_.read(reinterpret_cast<char*>(bytes_.data() + kBlockHeadBytes),
           static_cast<std::streamsize>(rest));
  if (static_cast<std::size_t>(in_.gcount()) != rest) {
    throw Error(where, which + ": read failed");
  }
  if (get<std::uint64_t>(bytes_.data() + kBlockHeadBytes + length) !=
      fnv1a(bytes_.data(), kBlockHeadBytes + length)) {
    throw Error(where, which + " is corrupt: checksum mismatch");
  }
  offset_ += block_bytes;
  block_frames_ = count;
  block_next_ = 0;
  return true;
}

bool RecordingReader::next(RecordedFrame& frame) {
  if (offset_ == file_size_ && block_next_ == block_frames_) {
    return false;
  }
  const std::string where = path_.string();
  if (header_.version >= 3) {
    if (block_next_ == block_frames_ && !read_block()) {
      return false;
    }
    const unsigned char* payload = bytes_.data() + kBlockHeadBytes + block_next_ * payload_size();
    if (const std::string problem = decode_checked(payload, frame); !problem.empty()) {
      throw Error(where, "frame " + std::to_string(frame_index_) + " is corrupt: " + problem);
    }
    ++block_next_;
    ++frame_index_;
    return true;
  }
  const std::string which =
      "frame " + std::to_string(frame_index_) + " (byte offset " + std::to_string(offset_) + ")";
  if (file_size_ - offset_ < bytes_.size()) {
    note_torn_end(file_size_ - offset_);
    return false;
  }
  in_.read(reinterpret_cast<char*>(bytes_.data()), static_cast<std::streamsize>(bytes_.size()));
  const auto got = static_cast<std::size_t>(in_.gcount());
  if (got != bytes_.size()) {
    throw Error(where, which + ": read failed");
  }
  if (get<std::uint32_t>(bytes_.data()) != kFrameMarker) {
    throw Error(where, which + " is corrupt: bad frame marker");
  }
  const std::size_t payload = payload_size();
  if (get<std::uint64_t>(bytes_.data() + 4 + payload) != fnv1a(bytes_.data() + 4, payload)) {
    throw Error(where, which + " is corrupt: checksum mismatch");
  }
  if (const std::string problem = decode_checked(bytes_.data() + 4, frame); !problem.empty()) {
    throw Error(where, which + " is corrupt: " + problem);
  }
  offset_ += got;
  ++frame_index_;
  return true;
}

Recording read_recording(const std::filesystem::path& path) {
  RecordingReader reader(path);
  Recording recording;
  recording.header = reader.header();
  recording.frames.reserve(reader.frame_count_hint());
  RecordedFrame frame;
  while (reader.next(frame)) {
    recording.frames.push_back(frame);
  }
  return recording;
}

RecordingScan scan_recording(const std::filesystem::path& path) {
  RecordingReader reader(path);
  RecordingScan scan;
  scan.header = reader.header();
  RecordedFrame frame;
  while (reader.next(frame)) {
    if (scan.frames == 0) {
      scan.first_frame = frame;
    }
    ++scan.frames;
  }
  scan.torn_bytes = reader.torn_bytes();
  return scan;
}

// ---------------------------------------------------------------------------------------------
// ReplayDevice

// The reader thread of a streamed replay and the ring it fills.
struct ReplayDevice::Stream {
  explicit Stream(std::size_t capacity) : ring(capacity) {}
  SpscRing<RecordedFrame> ring;
  std::thread thread;
  std::atomic<bool> stop{false};
  std::atomic<bool> done{false};  // the thread has pushed all it will (error_text is set first)
  std::string error_text;         // why it stopped early; read after done
  bool failed = false;            // the haptic side saw done with frames missing
};

ReplayDevice::ReplayDevice(DeviceProfile profile, std::vector<RecordedFrame> frames)
    : profile_(std::move(profile)), frames_(std::move(frames)), frame_count_(frames_.size()) {
  if (frames_.empty()) {
    throw Error("replay device '" + profile_.name + "'", "recording has no frames");
  }
  commands_.reserve(frames_.size());
}

ReplayDevice::ReplayDevice(DeviceProfile profile, std::filesystem::path recording,
                           std::size_t frame_count)
    : profile_(std::move(profile)), frame_count_(frame_count), path_(std::move(recording)) {
  if (frame_count_ == 0) {
    throw Error(path_.string(), "the recording has no frames");
  }
  start_stream();
}

ReplayDevice::~ReplayDevice() {
  stop_stream();
}

void ReplayDevice::start_stream() {
  stream_ = std::make_unique<Stream>(kReplayPrefetchFrames);
  Stream& st = *stream_;
  st.thread = std::thread([&st, path = path_, count = frame_count_] {
    try {
      RecordingReader reader(path, RecordingReader::TornEnd::kQuiet);
      RecordedFrame frame;
      std::size_t pushed = 0;
      while (pushed < count && !st.stop.load(std::memory_order_relaxed)) {
        if (!reader.next(frame)) {
          st.error_text = path.string() + ": the recording has " + std::to_string(pushed) +
                          " frames, fewer than the " + std::to_string(count) +
                          " it had when checked (changed meanwhile?)";
          break;
        }
        while (!st.ring.push(frame)) {  // the ring is full: the replay is far enough ahead
          if (st.stop.load(std::memory_order_relaxed)) {
            st.done.store(true, std::memory_order_release);
            return;
          }
          std::this_thread::sleep_for(std::chrono::microseconds(500));
        }
        ++pushed;
      }
    } catch (const std::exception& e) {
      st.error_text = e.what();
    }
    st.done.store(true, std::memory_order_release);
  });
  // The first frame is there before the first read(), so the loop does not start by waiting.
  while (st.ring.front() == nullptr && !st.done.load(std::memory_order_acquire)) {
    std::this_thread::sleep_for(std::chrono::microseconds(200));
  }
}

void ReplayDevice::stop_stream() noexcept {
  if (stream_ && stream_->thread.joinable()) {
    stream_->stop.store(true, std::memory_order_relaxed);
    stream_->thread.join();
  }
}

DeviceInput ReplayDevice::read(double /*time_s*/) noexcept {  // haptic path
  if (stream_) {
    Stream& st = *stream_;
    while (next_frame_ < frame_count_ && !st.failed) {
      if (const RecordedFrame* f = st.ring.front()) {
        last_input_ = f->input;
        st.ring.pop();
        ++next_frame_;
        break;
      }
      // Empty: the reader is behind (rare: it keeps kReplayPrefetchFrames ahead) or has stopped.
      if (st.done.load(std::memory_order_acquire) && st.ring.front() == nullptr) {
        st.failed = true;
        break;
      }
      std::this_thread::yield();
    }
    last_healthy_ = last_input_.healthy && !st.failed;
    return last_input_;
  }
  const std::size_t i = std::min(next_frame_, frames_.size() - 1);
  if (next_frame_ < frames_.size()) {
    ++next_frame_;
  }
  last_healthy_ = frames_[i].input.healthy;
  return frames_[i].input;
}

void ReplayDevice::write(const DeviceCommand& command) noexcept {
  if (commands_.size() < commands_.capacity()) {
    commands_.push_back(command);  // within the reserved capacity: no allocation
  }
}

DeviceStatus ReplayDevice::status() const noexcept {
  if (stream_ && stream_->failed) {
    return {DeviceHealth::kFailed, stream_->error_text};
  }
  if (!last_healthy_) {
    return {DeviceHealth::kFailed, "the recorded input was marked unhealthy"};
  }
  return {DeviceHealth::kConnected, {}};
}

void ReplayDevice::rewind() {
  next_frame_ = 0;
  last_healthy_ = true;
  commands_.clear();
  if (stream_) {
    stop_stream();
    start_stream();
  }
}

// ---------------------------------------------------------------------------------------------
// Comparison

RecordingDifference compare_frames(std::span<const RecordedFrame> expected,
                                   std::span<const RecordedFrame> actual) {
  RecordingDifference diff;
  std::vector<unsigned char> a(recorded_frame_size_bytes());
  std::vector<unsigned char> b(recorded_frame_size_bytes());
  const std::size_t common = std::min(expected.size(), actual.size());
  for (std::size_t i = 0; i < common; ++i) {
    encode_frame(expected[i], a.data());
    encode_frame(actual[i], b.data());
    if (a == b) {
      continue;
    }
    Flattener fa;
    Flattener fb;
    visit_frame(expected[i], fa);
    visit_frame(actual[i], fb);
    for (std::size_t k = 0; k < fa.entries.size(); ++k) {
      if (fa.entries[k].bytes != fb.entries[k].bytes) {
        diff.identical = false;
        diff.frame_index = i;
        diff.field = field_name(fa.entries[k].id);
        diff.expected_value = fa.entries[k].text;
        diff.actual_value = fb.entries[k].text;
        diff.message = "frame " + std::to_string(i) + ", " + diff.field + ": expected " +
                       diff.expected_value + ", got " + diff.actual_value;
        return diff;
      }
    }
  }
  if (expected.size() != actual.size()) {
    diff.identical = false;
    diff.field = "frame count";
    diff.expected_value = std::to_string(expected.size());
    diff.actual_value = std::to_string(actual.size());
    diff.message = "frame count: expected " + diff.expected_value + ", got " + diff.actual_value +
                   " (the first " + std::to_string(common) + " frames are identical)";
  }
  return diff;
}

RecordingDifference compare_recordings(const Recording& expected, const Recording& actual) {
  if (expected.header.scene_hash != actual.header.scene_hash) {
    RecordingDifference diff;
    diff.identical = false;
    diff.field = "header.scene_hash";
    diff.expected_value = expected.header.scene_hash;
    diff.actual_value = actual.header.scene_hash;
    diff.message = "header.scene_hash: expected '" + diff.expected_value + "', got '" +
                   diff.actual_value + "'";
    return diff;
  }
  return compare_frames(expected.frames, actual.frames);
}

RecordingDifference compare_recording_files(const std::filesystem::path& expected,
                                            const std::filesystem::path& actual) {
  RecordingReader a(expected, RecordingReader::TornEnd::kQuiet);
  RecordingReader b(actual, RecordingReader::TornEnd::kQuiet);
  if (a.header().scene_hash != b.header().scene_hash) {
    Recording ha;
    Recording hb;
    ha.header = a.header();
    hb.header = b.header();
    return compare_recordings(ha, hb);
  }
  RecordedFrame fa;
  RecordedFrame fb;
  std::size_t index = 0;
  for (;;) {
    const bool more_a = a.next(fa);
    const bool more_b = b.next(fb);
    if (more_a && more_b) {
      RecordingDifference d = compare_frames({&fa, 1}, {&fb, 1});
      if (!d.identical) {
        d.frame_index = index;
        d.message = "frame " + std::to_string(index) + d.message.substr(d.message.find(','));
        return d;
      }
      ++index;
      continue;
    }
    RecordingDifference d;
    if (more_a != more_b) {
      // Count the rest of the longer one, for the same message as compare_frames.
      std::size_t expected_count = index + (more_a ? 1 : 0);
      std::size_t actual_count = index + (more_b ? 1 : 0);
      while (more_a && a.next(fa)) {
        ++expected_count;
      }
      while (more_b && b.next(fb)) {
        ++actual_count;
      }
      d.identical = false;
      d.field = "frame count";
      d.expected_value = std::to_string(expected_count);
      d.actual_value = std::to_string(actual_count);
      d.message = "frame count: expected " + d.expected_value + ", got " + d.actual_value +
                  " (the first " + std::to_string(index) + " frames are identical)";
    }
    return d;
  }
}

}  // namespace hapsim
