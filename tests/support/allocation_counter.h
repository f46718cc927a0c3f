// Counting heap allocations in a test executable, to prove a haptic-path function allocates
// nothing: global operator new is replaced (allocation_counter.cpp) and counts every call.
#pragma once

namespace hapsim::test {

/// Allocations through operator new since the program started.
long allocation_count();

}  // namespace hapsim::test
