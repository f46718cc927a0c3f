// Cyclone DDS's C API behind small RAII types of our own (the C++ binding is not packaged for
// Debian 12; STACK.md). One owned dds_entity_t, deleted with its children when the owner goes.
#pragma once

#include <dds/dds.h>

#include <string_view>
#include <utility>

namespace hapsim::net {

/// Throws hapsim::Error("dds", "<what>: <Cyclone's reason>") when `rc` is negative; else
/// returns it.
dds_return_t check_dds(dds_return_t rc, std::string_view what);

class DdsEntity {
 public:
  DdsEntity() = default;
  explicit DdsEntity(dds_entity_t handle) noexcept : handle_(handle) {}
  DdsEntity(DdsEntity&& other) noexcept : handle_(std::exchange(other.handle_, 0)) {}
  DdsEntity& operator=(DdsEntity&& other) noexcept {
    if (this != &other) {
      reset();
      handle_ = std::exchange(other.handle_, 0);
    }
    return *this;
  }
  DdsEntity(const DdsEntity&) = delete;
  DdsEntity& operator=(const DdsEntity&) = delete;
  ~DdsEntity() { reset(); }

  [[nodiscard]] dds_entity_t get() const noexcept { return handle_; }
  [[nodiscard]] explicit operator bool() const noexcept { return handle_ > 0; }
  void reset() noexcept {
    if (handle_ > 0) {
      dds_delete(handle_);
    }
    handle_ = 0;
  }

 private:
  dds_entity_t handle_ = 0;
};

}  // namespace hapsim::net
