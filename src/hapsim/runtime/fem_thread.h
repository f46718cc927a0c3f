// The FEM bodies' own thread (architecture.md#deformation): while it runs, the world's steps only
// launch and adopt FEM updates (World::set_fem_deferred) and this thread runs each launched update
// as soon as it is launched, at its own rate, never in the 1 ms cycle. An update that is not
// ready one FEM period after its launch is adopted late by the haptic thread (counted).
#pragma once

#include <atomic>
#include <cstdint>
#include <string>
#include <thread>

namespace hapsim {

class World;

class FemThread {
 public:
  /// Starts the thread when `world` has FEM bodies (else does nothing). `world` must outlive it.
  explicit FemThread(World& world);
  /// Stops and joins; the world runs its FEM updates in its steps again.
  ~FemThread();
  FemThread(const FemThread&) = delete;
  FemThread& operator=(const FemThread&) = delete;

  [[nodiscard]] bool running() const { return thread_.joinable(); }
  /// Updates that threw (the thread stops updating at the first; the haptic path keeps the last
  /// models), and the error's text.
  [[nodiscard]] std::uint64_t failures() const { return failures_.load(); }
  [[nodiscard]] const std::string& error() const { return error_; }

 private:
  void run();

  World& world_;
  std::atomic<bool> stop_{false};
  std::atomic<std::uint64_t> failures_{0};
  std::string error_;
  std::thread thread_;
};

}  // namespace hapsim
