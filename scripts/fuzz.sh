#!/usr/bin/env bash
# Runs every libFuzzer target for SECONDS each (default 60) from its committed seed corpus
# (docs/fuzzing.md): builds them with Debian's clang in build/fuzz (ASan + UBSan), keeps what
# each run finds in build/fuzz/found/<target>/ (the committed seeds stay as they are), and prints
# one line per target: executions, coverage and whether it found anything. A crash, leak,
# timeout or failed check leaves its input in build/fuzz/artifacts/<target>/ and makes the
# script exit 1 after the other targets ran.
#
#   scripts/fuzz.sh [SECONDS] [TARGET...]
#
# HAPSIM_FUZZ_RUNS=N also stops each target after N executions (the long run: SECONDS=3600 and
# HAPSIM_FUZZ_RUNS=1000000 ends a target at 10^6 executions or an hour, whichever comes first).
set -uo pipefail
cd "$(dirname "${BASH_SOURCE[0]}")/.."
seconds="${1:-60}"
shift || true
all=(legacy_packet local_model device_state command view_state scene scene_step mesh mesh_soup trajectory
     number_csv recording urdf)
if [[ $# -eq 0 ]]; then
  targets=("${all[@]}")
else
  targets=("$@")
fi

export CMAKE_CXX_COMPILER_LAUNCHER="${CMAKE_CXX_COMPILER_LAUNCHER:-ccache}"
export CMAKE_C_COMPILER_LAUNCHER="${CMAKE_C_COMPILER_LAUNCHER:-ccache}"
# ccache caches files built with a precompiled header only with these (cmake/HapsimBuildSpeed.cmake).
export CCACHE_SLOPPINESS="${CCACHE_SLOPPINESS:-pch_defines,time_macros,include_file_mtime,include_file_ctime}"
if ! command -v ccache >/dev/null; then
  unset CMAKE_CXX_COMPILER_LAUNCHER CMAKE_C_COMPILER_LAUNCHER
fi
if [[ ! -f build/fuzz/CMakeCache.txt ]]; then
  cmake -S . -B build/fuzz -G Ninja -DCMAKE_C_COMPILER=clang-14 -DCMAKE_CXX_COMPILER=clang++-14 \
        -DCMAKE_BUILD_TYPE=RelWithDebInfo -DHAPSIM_FUZZ=ON -DHAPSIM_BUILD_TESTS=OFF \
        -DHAPSIM_BUILD_BENCH=OFF -DHAPSIM_REQUIRE_ORACLES=OFF >/dev/null || exit 2
fi
cmake --build build/fuzz -j2 --target "${targets[@]/#/hapsim_fuzz_}" || exit 2

# Per target: the largest input and the time one input may take (a scene generates a knee; a
# mesh is parsed in a child process with its own 30 s limit, below libFuzzer's).
declare -A max_len=([view_state]=8192 [scene]=8192 [scene_step]=8192 [mesh]=4096 [recording]=16384
                  [urdf]=8192)
declare -A timeout=([scene]=60 [scene_step]=60 [mesh]=60 [urdf]=20)
# Leaks inside a library we cannot fix, each with its reason (config/sanitizers/lsan.supp).
export LSAN_OPTIONS="suppressions=$PWD/config/sanitizers/lsan.supp${LSAN_OPTIONS:+:$LSAN_OPTIONS}"
status=0
for t in "${targets[@]}"; do
  found="build/fuzz/found/$t"
  artifacts="build/fuzz/artifacts/$t/"
  mkdir -p "$found" "$artifacts"
  log="build/fuzz/$t.log"
  build/fuzz/fuzz/hapsim_fuzz_"$t" -max_total_time="$seconds" ${HAPSIM_FUZZ_RUNS:+-runs="$HAPSIM_FUZZ_RUNS"} -print_final_stats=1 \
      -max_len="${max_len[$t]:-4096}" -timeout="${timeout[$t]:-10}" -rss_limit_mb=4096 \
      -artifact_prefix="$artifacts" "$found" "fuzz/corpus/$t" >"$log" 2>&1
  rc=$?
  runs=$(grep -o 'stat::number_of_executed_units: *[0-9]*' "$log" | grep -o '[0-9]*$')
  cov=$(grep -o 'cov: [0-9]*' "$log" | tail -1 | grep -o '[0-9]*')
  if [[ $rc -ne 0 ]]; then
    status=1
    echo "$t: FOUND something after ${runs:-?} executions (exit $rc): see $log and $artifacts"
  else
    took=$(grep -o 'Done [0-9]* runs in [0-9]* second' "$log" | grep -o 'in [0-9]*' | grep -o '[0-9]*')
    echo "$t: ${runs:-?} executions in ${took:-$seconds} s, coverage ${cov:-?} edges, nothing found"
  fi
done
exit $status
