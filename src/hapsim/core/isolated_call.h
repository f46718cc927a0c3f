// Running a third-party parser on an untrusted file in a child process (fork), so that a crash,
// a hang or a runaway allocation inside it (Assimp on a malformed PLY: an endless header loop, a
// segmentation fault, an assertion) becomes one hapsim::Error naming the file instead of taking
// the process down. The child gets a time and a memory limit (setrlimit) and hands its result
// back through a pipe as bytes. Loading is never on the haptic path: it can afford the fork.
#pragma once

#include <cstddef>
#include <functional>
#include <string>

namespace hapsim {

struct IsolationLimits {
  /// Wall-clock seconds before the child is killed.
  double time_s = 30.0;
  /// Bytes of address space the child may add to what it inherits (not enforced under the
  /// address, thread or memory sanitizer, whose shadow memory needs the whole address space).
  std::size_t memory_bytes = std::size_t{2} << 30;
};

/// Runs `work` in a child process and returns the bytes it returned. `where` names the input in
/// errors and `what` the parser ("the mesh importer (Assimp)"). Throws hapsim::Error(where, ...)
/// when the child dies on a signal, exceeds its limits or exits without a result; a hapsim::Error
/// (or other std::exception) thrown by `work` is rethrown in the caller with its where and text.
[[nodiscard]] std::string run_isolated(const std::string& where, const std::string& what,
                                       const IsolationLimits& limits,
                                       const std::function<std::string()>& work);

}  // namespace hapsim
