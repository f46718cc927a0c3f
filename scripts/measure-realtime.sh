#!/usr/bin/env bash
# Issue 5's figures: the haptic loop's rate, period jitter and missed deadlines over 60 s while the
# viewer renders the knee at 1280x720 on Mesa's software rasteriser (under Xvfb), the viewer's
# fps for the procedural knee and for the real VHF knee, and the loop alone (headless).
# Usage: bash scripts/measure-realtime.sh [SECONDS]   (default 60; results in build/measure/)
#        bash scripts/measure-realtime.sh --load [SECONDS]   (default 30 per run)
# --load (issue 14 item 6): the loop alone (hapsim run --realtime on the procedural knee), quiet and
# with the other core saturated (a busy loop pinned to CPU 1 for the run's length, then killed),
# each with SCHED_FIFO (as root) and with normal scheduling (as the user nobody, who may not ask
# for real-time priority: the ordinary user's case). Prints one markdown table row per run, with the
# load average at its start (other people's builds on a shared machine are load too).
set -euo pipefail
source "$(dirname "${BASH_SOURCE[0]}")/setup.sh"
bin="${HAPSIM_BUILD_DIR}/apps/hapsim"
out="${HAPSIM_ROOT}/build/measure"
mkdir -p "$out"

if [ "${1:-}" = "--load" ]; then
  seconds="${2:-30}"
  cmake --build "$HAPSIM_BUILD_DIR" --target hapsim
  scratch="$(mktemp -d)"
  chmod 755 "$scratch" && chown nobody "$scratch" 2>/dev/null || true
  echo "| scheduling | other core | load avg at start | rate | jitter p50 / p99 / max | missed (> 2 ms) | supervisor stalls / haptic gaps ramped | memory locked, haptic page faults |"
  echo "|---|---|---|---|---|---|---|---|"
  for sched in fifo normal; do
    for load in quiet busy; do
      json="$scratch/rt-$sched-$load.json"
      busy_pid=""
      if [ "$load" = busy ]; then
        # Bounded: the loop ends with the run, and `timeout` ends it anyway.
        taskset -c 1 timeout "$((seconds + 30))" bash -c 'while :; do :; done' &
        busy_pid=$!
      fi
      as=()
      if [ "$sched" = normal ]; then
        as=(setpriv --reuid=nobody --regid=nogroup --clear-groups --inh-caps=-all)
      fi
      loadavg="$(cut -d' ' -f1 /proc/loadavg)"
      "${as[@]}" "$bin" run "${HAPSIM_ROOT}/scenes/knee_procedural.json" -q --realtime \
        --duration "$seconds" --json "$json" > /dev/null
      if [ -n "$busy_pid" ]; then
        kill "$busy_pid" 2> /dev/null || true
        wait "$busy_pid" 2> /dev/null || true
      fi
      cp "$json" "$out/"
      python3 - "$json" "$load" "$loadavg" << 'PY'
import json, sys
j = json.load(open(sys.argv[1]))
rt = j["realtime"]
jit = rt["period_jitter_us"]
steps = j["steps"]
print(f"| {rt['scheduling']} | {sys.argv[2]} | {sys.argv[3]} | {rt['rate_hz']:.1f} Hz | "
      f"{jit['p50']:.1f} / {jit['p99']:.1f} / {jit['max'] / 1000:.1f} ms | "
      f"{rt['missed_deadlines']} in {steps} | {rt['stall_events']} / {rt['resume_gaps']} | "
      f"{'yes' if rt['memory_locked'] else 'no'}, {rt['haptic_page_faults']} |")
PY
    done
  done
  # The platform's floor: a probe that does nothing but sleep to absolute 1 ms deadlines at
  # SCHED_FIFO 80 (no hapsim code at all), under the same two conditions.
  cat > "$scratch/probe.c" << 'C'
#include <sched.h>
#include <stdio.h>
#include <stdlib.h>
#include <time.h>
static long long now_ns(void) {
  struct timespec t; clock_gettime(CLOCK_MONOTONIC, &t); return t.tv_sec * 1000000000LL + t.tv_nsec;
}
static int cmp(const void* a, const void* b) {
  long long x = *(const long long*)a, y = *(const long long*)b; return (x > y) - (x < y);
}
int main(int argc, char** argv) {
  const int n = atoi(argv[1]) * 1000;
  struct sched_param p = {.sched_priority = 80};
  const int fifo = sched_setscheduler(0, SCHED_FIFO, &p) == 0;
  long long* jitter = malloc(sizeof(long long) * n);
  long long deadline = now_ns(), previous = deadline;
  int missed = 0;
  for (int i = 0; i < n; ++i) {
    deadline += 1000000;
    struct timespec d = {deadline / 1000000000LL, deadline % 1000000000LL};
    clock_nanosleep(CLOCK_MONOTONIC, TIMER_ABSTIME, &d, NULL);
    const long long t = now_ns(), period = t - previous;
    previous = t;
    if (t - deadline > 1000000) deadline = t;
    jitter[i] = llabs(period - 1000000);
    missed += period > 2000000;
  }
  qsort(jitter, n, sizeof(long long), cmp);
  printf("| probe (%s) | %%s | %%s | - | %.1f / %.1f / %.1f ms | %d in %d | - | - |\n", fifo ? "SCHED_FIFO" : "normal",
         jitter[n / 2] / 1e3, jitter[(long)(n * 0.99)] / 1e3, jitter[n - 1] / 1e6, missed, n);
  return 0;
}
C
  cc -O2 -o "$scratch/probe" "$scratch/probe.c"
  for load in quiet busy; do
    busy_pid=""
    if [ "$load" = busy ]; then
      taskset -c 1 timeout "$((seconds + 30))" bash -c 'while :; do :; done' &
      busy_pid=$!
    fi
    loadavg="$(cut -d' ' -f1 /proc/loadavg)"
    # shellcheck disable=SC2059  # the probe prints the row's format
    printf "$("$scratch/probe" "$seconds")\n" "$load" "$loadavg"
    if [ -n "$busy_pid" ]; then
      kill "$busy_pid" 2> /dev/null || true
      wait "$busy_pid" 2> /dev/null || true
    fi
  done
  rm -rf "$scratch"
  echo "hapsim: JSON in $out (rt-*.json)"
  exit 0
fi

hapsim_install_packages
hapsim_build
seconds="${1:-60}"
xvfb=(xvfb-run -a -s "-screen 0 1280x720x24")

echo "== haptic loop alone, ${seconds} s (hapsim run --realtime)"
"$bin" run "${HAPSIM_ROOT}/scenes/knee_procedural.json" -q --realtime --duration "$seconds" \
  --json "$out/loop-alone.json" | grep -E "real time|step cost"

echo "== viewer on the procedural knee, ${seconds} s, scripted palpation, no vsync"
"${xvfb[@]}" "$bin" view "${HAPSIM_ROOT}/scenes/knee_procedural.json" --device sim --no-vsync \
  --duration "$seconds" --json "$out/view-knee.json" --screenshot "$out/view-knee.png"

echo "== the same with the 3D view filling the window (no panels)"
"${xvfb[@]}" "$bin" view "${HAPSIM_ROOT}/scenes/knee_procedural.json" --device sim --no-vsync --no-panels \
  --duration "$((seconds < 20 ? seconds : 20))" --json "$out/view-knee-nopanels.json"

data="${HAPSIM_ROOT}/../shared/data/knee_vhf_left"
if [ -d "$data" ]; then
  echo "== viewer on the real VHF knee (5 fingertips), 20 s"
  "${xvfb[@]}" "$bin" view "${HAPSIM_ROOT}/scenes/knee_vhf.json" --data "$data" --device sim \
    --no-vsync --duration 20 --json "$out/view-vhf.json" --screenshot "$out/view-vhf.png"
else
  echo "== real VHF knee skipped: $data not found"
fi
echo "hapsim: JSON and screenshots in $out"
