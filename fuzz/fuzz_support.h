// What the fuzz entry points share: a check that aborts with a message (libFuzzer saves the
// input; the ctest replay fails), and a reader that takes a message's fields in declaration
// order from the raw bytes, zero-filled past the end, so any input is a sample.
#pragma once

#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>

#define HAPSIM_FUZZ_CHECK(condition, what)                                                  \
  do {                                                                                      \
    if (!(condition)) {                                                                     \
      std::fprintf(stderr, "%s:%d: fuzz check failed: %s (%s)\n", __FILE__, __LINE__, what, \
                   #condition);                                                             \
      std::abort();                                                                         \
    }                                                                                       \
  } while (false)

namespace hapsim::fuzz {

class FieldReader {
 public:
  FieldReader(const std::uint8_t* data, std::size_t size) : data_(data), size_(size) {}

  /// The next sizeof(T) bytes as a T (host byte order, as the DDS deserializer leaves them).
  template <typename T>
  void read(T& out) {
    unsigned char bytes[sizeof(T)] = {};
    const std::size_t n =
        position_ < size_ ? (size_ - position_ < sizeof(T) ? size_ - position_ : sizeof(T)) : 0;
    if (n > 0) {
      std::memcpy(bytes, data_ + position_, n);
    }
    position_ += sizeof(T);
    std::memcpy(&out, bytes, sizeof(T));
  }
  template <typename T, std::size_t N>
  void read(T (&out)[N]) {
    for (T& element : out) {
      read(element);
    }
  }
  /// A CDR boolean: Cyclone's deserializer refuses a byte above 1, so a sample's bool is 0 or 1
  /// (reading another value into a C++ bool would be undefined behaviour, not a DDS input).
  void read_bool(bool& out) {
    std::uint8_t byte = 0;
    read(byte);
    out = (byte & 1U) != 0;
  }

 private:
  const std::uint8_t* data_;
  std::size_t size_;
  std::size_t position_ = 0;
};

}  // namespace hapsim::fuzz
