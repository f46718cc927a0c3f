#!/usr/bin/env bash
# Runs hapsim under the sanitizers (docs/sanitizers.md). Each part builds in its own folder with
# its CMake preset (the build at `nice`, two jobs; the tests not) and fails on any report not
# suppressed, with its reason, in config/sanitizers/.
#
#   scripts/check-sanitizers.sh [quick|asan|tsan|all]...      (default: all)
#
#   quick  ASan + UBSan replays of the packet and file fuzz entry points (seed corpus + seeded
#          random inputs) on the lower layers only: build/sanitize-quick, about 2-3 min cold.
#          scripts/run-tests.sh (CI) runs this part; HAPSIM_SKIP_SANITIZERS=1 skips it there.
#   asan   the whole suite under ASan + UBSan (Debug): build/asan, a full cold build (~1 h on two
#          shared cores) and a run about 5x slower than release.
#   tsan   the threaded layers' tests (core, device, runtime: triple buffer, SPSC ring, haptic
#          loop, sessions, the interactive device) under TSan: build/tsan.
set -euo pipefail
cd "$(dirname "${BASH_SOURCE[0]}")/.."

export CMAKE_CXX_COMPILER_LAUNCHER="${CMAKE_CXX_COMPILER_LAUNCHER:-ccache}"
export CMAKE_C_COMPILER_LAUNCHER="${CMAKE_C_COMPILER_LAUNCHER:-ccache}"
# ccache caches files built with a precompiled header only with these (cmake/HapsimBuildSpeed.cmake).
export CCACHE_SLOPPINESS="${CCACHE_SLOPPINESS:-pch_defines,time_macros,include_file_mtime,include_file_ctime}"
if ! command -v ccache >/dev/null; then
  unset CMAKE_CXX_COMPILER_LAUNCHER CMAKE_C_COMPILER_LAUNCHER
fi
# Idle CPU only by default: a developer's other work (and other people's builds) come first.
nice_level="${HAPSIM_SANITIZER_NICE:-19}"

parts=("$@")
if [[ ${#parts[@]} -eq 0 || "${parts[0]}" == all ]]; then
  parts=(quick asan tsan)
fi

run_part() {
  local preset="$1" started=$SECONDS
  if [[ ! -f "build/$preset/build.ninja" ]]; then
    cmake --preset "$preset" >/dev/null
  fi
  nice -n "$nice_level" cmake --build --preset "$preset"
  local built=$((SECONDS - started))
  # ctest output names every failing test; the sanitizer's report is in its output. Not at `nice`:
  # starved behind other work, tests with time limits failed on the wait (a crashing child's
  # report took over 10 s; a 3 s test took 122 s), not on what they check.
  ctest --preset "$preset"
  echo "check-sanitizers: $preset clean (build ${built} s, tests $((SECONDS - started - built)) s)"
}

for part in "${parts[@]}"; do
  case "$part" in
    quick) run_part sanitize-quick ;;
    asan) run_part asan ;;
    tsan) run_part tsan ;;
    *)
      echo "check-sanitizers: unknown part '$part' (quick, asan, tsan or all)" >&2
      exit 2
      ;;
  esac
done
