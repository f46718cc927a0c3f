// Which sanitizers the including translation unit is built with, as 0/1 macros for `#if` and as
// constants for `if constexpr`. One place for the detection, because the compilers disagree: GCC
// defines __SANITIZE_ADDRESS__ and __SANITIZE_THREAD__ (and nothing for -fsanitize=leak alone);
// Clang 14 answers __has_feature(...) instead.
#pragma once

#if defined(__has_feature)
#define HAPSIM_HAS_FEATURE(feature) __has_feature(feature)
#else
#define HAPSIM_HAS_FEATURE(feature) 0
#endif

#if defined(__SANITIZE_ADDRESS__) || HAPSIM_HAS_FEATURE(address_sanitizer)
#define HAPSIM_ADDRESS_SANITIZER 1
#else
#define HAPSIM_ADDRESS_SANITIZER 0
#endif

#if defined(__SANITIZE_THREAD__) || HAPSIM_HAS_FEATURE(thread_sanitizer)
#define HAPSIM_THREAD_SANITIZER 1
#else
#define HAPSIM_THREAD_SANITIZER 0
#endif

#if HAPSIM_HAS_FEATURE(memory_sanitizer)
#define HAPSIM_MEMORY_SANITIZER 1
#else
#define HAPSIM_MEMORY_SANITIZER 0
#endif

// LeakSanitizer comes with AddressSanitizer; alone, only Clang says so.
#if HAPSIM_ADDRESS_SANITIZER || HAPSIM_HAS_FEATURE(leak_sanitizer)
#define HAPSIM_LEAK_SANITIZER 1
#else
#define HAPSIM_LEAK_SANITIZER 0
#endif

// A sanitizer that reserves terabytes of shadow memory and intercepts signals and fork().
#define HAPSIM_SHADOW_SANITIZER \
  (HAPSIM_ADDRESS_SANITIZER || HAPSIM_THREAD_SANITIZER || HAPSIM_MEMORY_SANITIZER)

namespace hapsim {

inline constexpr bool kBuiltWithLeakSanitizer = HAPSIM_LEAK_SANITIZER != 0;
inline constexpr bool kBuiltWithShadowSanitizer = HAPSIM_SHADOW_SANITIZER != 0;

}  // namespace hapsim
