#!/usr/bin/env bash
# Issue 5's figures: the haptic loop's rate, period jitter and missed deadlines over 60 s while the
# viewer renders the knee at 1280x720 on Mesa's software rasteriser (under Xvfb), the viewer's
# fps for the procedural knee and for the real VHF knee, and the loop alone (headless).
# Usage: bash scripts/measure-realtime.sh [SECONDS]   (default 60; results in build/measure/)
set -euo pipefail
source "$(dirname "${BASH_SOURCE[0]}")/setup.sh"
hapsim_install_packages
hapsim_build
seconds="${1:-60}"
bin="${HAPSIM_BUILD_DIR}/apps/hapsim"
out="${HAPSIM_ROOT}/build/measure"
mkdir -p "$out"
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
