#!/usr/bin/env bash
# The viewer under a virtual X display, driven by the real X pointer (xdotool): opens the knee
# scene with the mouse probe, pushes the probe into the knee with the wheel, drags it a little,
# and lets the viewer write its first and last frames and its JSON summary.
# Usage: viewer_smoke.sh HAPSIM_BIN SCENE OUT_DIR   (run inside xvfb-run)
set -euo pipefail
bin="$1" scene="$2" out="$3"
mkdir -p "$out"
"$bin" view "$scene" --device mouse --duration 12 --size 1280x720 \
  --first-screenshot "$out/first.png" --screenshot "$out/last.png" --json "$out/view.json" \
  > "$out/view.log" 2>&1 &
viewer=$!
# Wait for the window, then put the pointer over the middle of the 3D view.
window=$(xdotool search --sync --onlyvisible --name hapsim | head -n 1)
xdotool windowactivate --sync "$window" 2>/dev/null || true
sleep 1.5
xdotool mousemove --window "$window" 640 330
# The window opens before the scene is loaded: wait for the viewer's third frame (its first
# screenshot, taken before the probe moves), however long a loaded machine takes to get there.
for _ in $(seq 1 1200); do
  [[ -s "$out/first.png" ]] && break
  sleep 0.1
done
# Wheel up = push the probe away from the viewer, into the knee (2 mm a step).
xdotool click --repeat 34 --delay 40 4
sleep 1
# Drag it sideways while it presses: left button, 30 px right, 10 px down.
xdotool mousedown 1
for _ in $(seq 1 10); do
  xdotool mousemove_relative -- 3 1
  sleep 0.05
done
xdotool mouseup 1
wait "$viewer"
