#!/usr/bin/env bash
# Every picture in docs/images, drawn by hapsim itself: the viewer's screenshots (under Xvfb),
# offscreen snapshots (EGL), the Python examples' plots and the assessment report's own pictures.
# Re-run it when what the program draws changes, look at the pictures, and commit them:
#   bash scripts/make-doc-images.sh [OUT_DIR] [HAPSIM_BINARY]
# OUT_DIR defaults to docs/images, HAPSIM_BINARY to build/release/apps/hapsim; the Python module
# is taken from the same build (HAPSIM_BINARY/../../python). The real-data pictures (the GP7, the
# full VHF knee) use $HAPSIM_DATA, else ../shared/data; without the data they are skipped, and
# the script says so ("skipped NAME: ..."). Needs xvfb-run (xvfb, xauth) and Debian's python3
# with matplotlib (scripts/setup.sh installs them). tests/apps/doc_images_test.cpp runs it and
# compares each picture with the committed one (docs/testing.md, "Documentation pictures").
#
# The viewer runs in real time: its screenshot is the last frame drawn before --duration, which
# on a loaded machine may be seconds old. So each screenshot is of a scene holding still for the
# last 3 s or more (a press held by cutting the scene's script there, the ball at rest at the end
# of the pick-and-place), and a frame drawn late draws the same picture.
set -euo pipefail

ROOT="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
OUT="${1:-${ROOT}/docs/images}"
HAPSIM="${2:-${ROOT}/build/release/apps/hapsim}"
PYTHON="${HAPSIM_PYTHON:-/usr/bin/python3}"
DATA="${HAPSIM_DATA:-${ROOT}/../shared/data}"

die() {
  echo "make-doc-images: $*" >&2
  exit 2
}
[ -x "$HAPSIM" ] || die "no hapsim binary at $HAPSIM (build it: cmake --build build/release --target hapsim)"
HAPSIM="$(cd "$(dirname "$HAPSIM")" && pwd)/$(basename "$HAPSIM")"
PYMODULE="$(cd "$(dirname "$HAPSIM")/.." && pwd)/python"
command -v xvfb-run >/dev/null || die "xvfb-run missing (apt-get install xvfb xauth; scripts/setup.sh does)"
"$PYTHON" -c "import matplotlib" 2>/dev/null ||
  die "$PYTHON cannot import matplotlib (apt-get install python3-matplotlib; scripts/setup.sh does)"
PYTHONPATH="$PYMODULE" "$PYTHON" -c "import hapsim" 2>/dev/null ||
  die "the hapsim Python module is not in $PYMODULE (build it: cmake --build build/release --target hapsim_python)"
mkdir -p "$OUT"
OUT="$(cd "$OUT" && pwd)"
S="${ROOT}/scenes"
WORK="$(mktemp -d)"
trap 'rm -rf "$WORK"' EXIT

# --- The viewer (one virtual X server for all of them; 1280x720, panels shown) -------------------
# `viewer NAME SCENE SECONDS [ARGS...]`: the viewer for SECONDS, its last frame to NAME.png.
# `held SCENE CUT [DATA]`: the scene's own script up to CUT seconds as a trajectory CSV (every
# 5 ms); played with --device sim:FILE the device then stays where the script was at CUT.
viewer_shots() {
  set -euo pipefail
  cd "$WORK" # the trajectories by their bare names: the panels show them, the same every run
  viewer() {
    local name="$1" scene="$2" seconds="$3"
    shift 3
    "$HAPSIM" view "$scene" --duration "$seconds" --no-vsync --size 1280x720 \
      --screenshot "$OUT/$name.png" "$@" >"$WORK/$name.log" 2>&1 ||
      { cat "$WORK/$name.log" >&2; echo "make-doc-images: $name failed" >&2; return 1; }
  }
  held() {
    PYTHONPATH="$PYMODULE" "$PYTHON" - "$@" <<'PY'
import sys
import hapsim
scene, cut = sys.argv[1], float(sys.argv[2])
world = hapsim.World(scene, data_dir=sys.argv[3] if len(sys.argv) > 3 else None)
rows = [world.script_input(k * 0.005) for k in range(int(round(cut / 0.005)) + 1)]
fingers, joints = len(rows[0].finger_rad), len(rows[0].joint_rad)
print(",".join(["t", "x", "y", "z", "qw", "qx", "qy", "qz"] + [f"f{i}" for i in range(fingers)]
               + [f"j{i}" for i in range(joints)] + ["buttons"]))
for k, d in enumerate(rows):
    values = [k * 0.005, *d.p_world, *d.q_world, *d.finger_rad, *d.joint_rad]
    print(",".join(f"{v:.17g}" for v in values) + f",{d.buttons}")
PY
  }
  # The default scene (the FEM knee): its script cut at 1.7 s, the fingertip in its first press,
  # over the lateral collateral ligament, and held there.
  held "$S/knee.json" 1.7 >knee-lcl-press.csv
  viewer viewer-knee "$S/knee.json" 4.5 --device sim:knee-lcl-press.csv
  # The pick-and-place at its end: the ball let go on the sheet (8.5 s), the arm back up and
  # still from 9.5 s.
  viewer viewer-teleop "$S/teleop.json" 12.5 --device sim
  if [ -f "$DATA/motoman_gp7/gp7.urdf" ]; then
    viewer viewer-teleop-gp7 "$S/teleop_gp7.json" 12.5 --device sim --data "$DATA/motoman_gp7"
  else
    echo "skipped viewer-teleop-gp7: no Motoman GP7 URDF in $DATA/motoman_gp7 (set HAPSIM_DATA)"
  fi
  # The full-resolution VHF knee: its script cut at 1.6 s, the five fingertips in their first
  # press, over the LCL and the fibular head, held there; seen from the front and lateral side.
  if [ -d "$DATA/knee_vhf_left" ]; then
    held "$S/knee_vhf.json" 1.6 "$DATA/knee_vhf_left" >knee-vhf-lcl-press.csv
    viewer viewer-knee-vhf "$S/knee_vhf.json" 4.5 --device sim:knee-vhf-lcl-press.csv \
      --data "$DATA/knee_vhf_left" --camera -0.40,0.22,0.08,-0.02,0.0,0.0,36
  else
    echo "skipped viewer-knee-vhf: no VHF knee in $DATA/knee_vhf_left (set HAPSIM_DATA)"
  fi
}

# --- Offscreen: snapshots, the Python examples' plots, the assessment report's pictures ----------
offscreen() {
  set -euo pipefail
  local run=("$HAPSIM" run -q --size 1280x720)
  # The glove hand pressing the procedural knee 1.6 s in (index on the patella, middle finger on
  # the patellar tendon), from the scene's "fig6" view, and framed on the contact as a red–cyan
  # anaglyph.
  "${run[@]}" "$S/knee_hand_procedural.json" --duration 1.6 --view fig6 \
    --snapshot "$OUT/snapshot-knee-hand-fig6.png" >/dev/null
  "${run[@]}" "$S/knee_hand_procedural.json" --duration 1.6 --stereo anaglyph \
    --snapshot "$OUT/snapshot-knee-hand-anaglyph.png" >/dev/null
  # The examples of docs/python.md, whole (not --quick).
  local example
  for example in stiffness_sweep contact_methods glove_palpation; do
    PYTHONPATH="$PYMODULE" MPLBACKEND=Agg "$PYTHON" "$ROOT/examples/python/$example.py" \
      --out "$WORK/python" >"$WORK/$example.log" 2>&1 ||
      { cat "$WORK/$example.log" >&2; echo "make-doc-images: $example.py failed" >&2; return 1; }
    cp "$WORK/python/python_$example.png" "$OUT/"
  done
  # docs/assessment-report.md: three scripted sessions on the paper knee standing in for a
  # trainee's first three (the shipped palpation cut at 6 s and 10 s, then whole), assessed as a
  # series. The report's pictures of the third (the scene at its end, the total force) and the
  # summary's learning curve.
  local paper="$S/knee_paper.json"
  "${run[@]}" "$paper" --duration 6 --record "$WORK/s1.rec" >/dev/null
  "${run[@]}" "$paper" --duration 10 --record "$WORK/s2.rec" >/dev/null
  "${run[@]}" "$paper" --record "$WORK/s3.rec" >/dev/null
  "$HAPSIM" assess "$WORK/s1.rec" "$WORK/s2.rec" "$WORK/s3.rec" --summary \
    --report "$WORK/assess" >"$WORK/assess.log" 2>&1 ||
    { cat "$WORK/assess.log" >&2; echo "make-doc-images: hapsim assess failed" >&2; return 1; }
  cp "$WORK/assess/session-03/picture.png" "$OUT/assessment_picture.png"
  cp "$WORK/assess/session-03/force_total.png" "$OUT/assessment_force_total.png"
  cp "$WORK/assess/learning_curve.png" "$OUT/assessment_learning_curve.png"
}

# The viewer mostly waits for its clock, the rest mostly computes: the two run side by side.
export HAPSIM OUT WORK S DATA PYTHON PYMODULE
offscreen &
offscreen_pid=$!
status=0
xvfb-run -a -s "-screen 0 1280x720x24" bash -c "$(declare -f viewer_shots); viewer_shots" ||
  status=$?
wait "$offscreen_pid" || status=$?
[ "$status" -eq 0 ] || die "failed (status $status)"
echo "make-doc-images: pictures in $OUT"
