#include "support/allocation_counter.h"

#include <atomic>
#include <cstdlib>
#include <new>

// GCC flags free() on memory from the replaced operator new as mismatched; here it is the pair.
#pragma GCC diagnostic ignored "-Wmismatched-new-delete"

namespace {
std::atomic<long> g_allocations{0};
thread_local long t_allocations = 0;
}  // namespace

void* operator new(std::size_t size) {
  g_allocations.fetch_add(1, std::memory_order_relaxed);
  ++t_allocations;
  if (void* p = std::malloc(size == 0 ? 1 : size)) {
    return p;
  }
  throw std::bad_alloc();
}
void operator delete(void* p) noexcept {
  std::free(p);
}
void operator delete(void* p, std::size_t /*size*/) noexcept {
  std::free(p);
}

namespace hapsim::test {

long allocation_count() {
  return g_allocations.load(std::memory_order_relaxed);
}

}  // namespace hapsim::test

namespace hapsim::test {

long thread_allocation_count() {
  return t_allocations;
}

}  // namespace hapsim::test
