// Counting heap allocations in a test executable, to prove a haptic-path function allocates
// nothing: global operator new is replaced (allocation_counter.cpp) and counts every call.
#pragma once

namespace hapsim::test {

/// Allocations through operator new since the program started.
long allocation_count();
/// Allocations through operator new made by the calling thread (a haptic thread proves its own
/// cycles allocate nothing while other threads go on as they like).
long thread_allocation_count();

}  // namespace hapsim::test
