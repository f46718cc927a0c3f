#include "hapsim/runtime/fem_thread.h"

#include "hapsim/world/world.h"

#include <chrono>
#include <exception>

namespace hapsim {

FemThread::FemThread(World& world) : world_(world) {
  if (world_.fem() == nullptr) {
    return;
  }
  world_.set_fem_deferred(true);
  thread_ = std::thread([this] { run(); });
}

FemThread::~FemThread() {
  if (thread_.joinable()) {
    stop_.store(true);
    thread_.join();
    world_.set_fem_deferred(false);
  }
}

void FemThread::run() {
  while (!stop_.load(std::memory_order_relaxed)) {
    bool ran = false;
    try {
      ran = world_.advance_fem();
    } catch (const std::exception& e) {
      error_ = e.what();
      failures_.fetch_add(1);
      return;
    }
    if (!ran) {
      // Launches come once per FEM period (several ms): a short nap costs little latency.
      std::this_thread::sleep_for(std::chrono::microseconds(200));
    }
  }
}

}  // namespace hapsim
