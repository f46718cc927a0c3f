// Support for LeakSanitizer builds (the `asan` preset, the fuzz targets). No effect otherwise.
#pragma once

namespace hapsim {

// Keeps every shared library mapped now loaded until the process exits.
//
// Why: LeakSanitizer reports at exit and counts memory reachable from a loaded library's globals
// as in use. Mesa's GL driver, loaded by a window or an EGL context, caches allocations in its
// globals; glfwTerminate()/eglTerminate() unload it before the exit, and those caches are then
// reported as leaks "from <unknown module>", which no suppression can name. Keeping the driver
// mapped lets LeakSanitizer see them for what they are. (Unwinding through the driver to name it
// needs ASan's slow unwinder, which deadlocks against LLVM's JIT in llvmpipe: docs/sanitizers.md.)
// Call after the GL context exists. Not on the haptic path.
void keep_libraries_mapped_for_leak_check();

// True in a build with AddressSanitizer or LeakSanitizer, where the call above has its effect.
[[nodiscard]] bool built_with_leak_checks();

}  // namespace hapsim
