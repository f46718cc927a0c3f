#!/usr/bin/env bash
# The papers' figures, redrawn by hapsim with no display (EGL offscreen; docs/figures.md shows
# them beside the papers' captions). Every scene, moment, camera and overlay is here, so anyone
# can re-run it:
#   bash scripts/make-figures.sh [OUT_DIR] [HAPSIM_BINARY]
# OUT_DIR defaults to docs/figures, HAPSIM_BINARY to build/release/apps/hapsim. The Gaussian
# profile plot needs Debian's python3 with python3-matplotlib (scripts/setup.sh installs it).
set -euo pipefail

ROOT="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
OUT="${1:-${ROOT}/docs/figures}"
HAPSIM="${2:-${ROOT}/build/release/apps/hapsim}"
PYTHON="${HAPSIM_PYTHON:-/usr/bin/python3}"
SIZE=1280x720

if [ ! -x "$HAPSIM" ]; then
  echo "make-figures: no hapsim binary at $HAPSIM (build it: cmake --build build/release --target hapsim)" >&2
  exit 2
fi
if ! "$PYTHON" -c "import matplotlib" 2>/dev/null; then
  echo "make-figures: $PYTHON cannot import matplotlib (apt-get install python3-matplotlib; scripts/setup.sh does)" >&2
  exit 2
fi
mkdir -p "$OUT"
S="${ROOT}/scenes"
run() { "$HAPSIM" run -q --size "$SIZE" "$@" >/dev/null; }

# --- Paper 000 (teleoperation, the virtual sheet) ---------------------------------------------
# Fig. 2: a sphere transcribed on the sheet. The hand has pressed the ball into the sheet and let
# go; it rests in its own imprint (the softer sheet of hand_ball_sheet, 0.5 N/mm: the teleop
# sheet's 3 N/mm dent under a 100 g ball is a quarter of a millimetre).
run "$S/hand_ball_sheet.json" --camera 0.32,-0.2,0.16,0.12,0.0,0.055,32 \
  --snapshot "$OUT/000-fig2-sphere-on-sheet.png"
# Fig. 3: the Gaussian deformation model, sampled by the model's own code.
"$HAPSIM" sheet-profile "$S/teleop.json" --force 1,2,4 --out "$OUT/000-fig3-gaussian-profile.csv" >/dev/null
"$PYTHON" "${ROOT}/scripts/plot-sheet-profile.py" "$OUT/000-fig3-gaussian-profile.csv" \
  "$OUT/000-fig3-gaussian-profile.png"
rm -f "$OUT/000-fig3-gaussian-profile.csv"
# §4's scene: the master arm (beside, as rods) drives the Motoman carrying the ball to the sheet.
# Cut short mid-carry, the run reports the pick-and-place unfinished (exit status 1): expected.
run "$S/teleop.json" --duration 6.5 --snapshot "$OUT/000-teleop-scene.png" || [ $? -eq 1 ]

# --- Paper 001 (knee palpation) on the paper's model of the real knee, the glove's index pressing the vastus medialis
# (scenes/knee_hand_paper.json: the finger reaches the skin at ~1.15 s, holds pressed 1.4-2.0 s) ---
KNEE_HAND="$S/knee_hand_paper.json"
MUSCLE=Muscle_VastusMedialis
CLOSE=0.26,0.14,0.14,0.025,0.04,0.095,30
# Fig. 3: the muscle's vertex groups coloured, their spheres of influence, and the three vertices
# closest in angle to the fingertip, through the skin and just short of the muscle.
run "$KNEE_HAND" --duration 1.18 --only-segments "$MUSCLE" --colours groups \
  --overlay influence,contact-vertices --camera "$CLOSE" --snapshot "$OUT/001-fig3-collision-detection.png"
# Fig. 5: the same segment dented by the fingertip, held pressed, seen across the press so the
# dent shows in the outline.
run "$KNEE_HAND" --duration 1.8 --only-segments "$MUSCLE" --colours groups --overlay influence \
  --camera 0.2,-0.06,0.12,0.02,0.03,0.09,36 --snapshot "$OUT/001-fig5-deformed-segment.png"
# Fig. 6: the hand touching the muscle in the room (the skin hidden: the paper's model went "from
# the inner layer of skin to bones"), seen from the medial side so the pressing index finger and
# the curled others show; the scene's own "fig6" view (from the front) hides the finger behind
# the hand.
run "$KNEE_HAND" --duration 1.8 --camera 0.5,0.12,0.21,0.0,0.03,0.12,40 --room --hide-segments Skin \
  --snapshot "$OUT/001-fig6-hand-touching-muscle.png"

echo "make-figures: 6 figures in $OUT"
