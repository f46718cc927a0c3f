#!/usr/bin/env bash
# The viewer's partial frames under a virtual X display: the knee palpation on the scripted device
# with the panels redrawn at most every 20 s, so between them the viewer draws and presents the 3D
# view alone. Two grabs of what the X server shows, a second apart, then Escape ends the viewer
# (its --duration only bounds a hang: a slow build must not end before the grabs), and its JSON.
# Usage: viewer_partial_frames.sh HAPSIM_BIN GRAB_BIN SCENE OUT_DIR   (run inside xvfb-run)
set -euo pipefail
bin="$1" grab="$2" scene="$3" out="$4"
mkdir -p "$out"
"$bin" view "$scene" --device sim --duration 120 --size 1280x720 --no-vsync --panels-hz 0.05 \
  --first-screenshot "$out/first.png" --json "$out/view.json" > "$out/view.log" 2>&1 &
viewer=$!
window=$(xdotool search --sync --onlyvisible --name hapsim | head -n 1)
# The pointer over the 3D view, where it does not ask the panels to be redrawn.
xdotool mousemove --window "$window" 640 360
# The window opens before the scene is loaded: wait for the viewer's third frame (its first
# screenshot), however long a loaded machine takes to get there.
for _ in $(seq 1 1200); do
  [[ -s "$out/first.png" ]] && break
  sleep 0.1
done
sleep 1
"$grab" "$out/grab1.png"
sleep 1
"$grab" "$out/grab2.png"
# Held until the viewer has gone: it reads the key once a frame, and a slow frame takes seconds.
xdotool keydown Escape
wait "$viewer"
xdotool keyup Escape || true
