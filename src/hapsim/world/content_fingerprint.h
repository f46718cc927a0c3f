// FNV-1a, 64 bit: the stable content fingerprint recordings carry (content_hash(), not a security
// hash). Public so that a controller (world_controller.h) can add what makes its worlds step
// differently.
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>

namespace hapsim {

class ContentFingerprint {
 public:
  void bytes(const void* data, std::size_t n) noexcept {
    const auto* p = static_cast<const unsigned char*>(data);
    for (std::size_t i = 0; i < n; ++i) {
      h_ = (h_ ^ p[i]) * 1099511628211ULL;
    }
  }
  void number(double x) noexcept { bytes(&x, sizeof x); }
  void text(const std::string& s) noexcept {
    bytes(s.data(), s.size());
    number(static_cast<double>(s.size()));
  }
  [[nodiscard]] std::uint64_t value() const noexcept { return h_; }

 private:
  std::uint64_t h_ = 14695981039346656037ULL;
};

}  // namespace hapsim
