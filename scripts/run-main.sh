#!/usr/bin/env bash
# The main job: install what is missing, build, then run the knee palpation scene on the simulated
# device (scenes/knee.json: the FEM knee, the real Visible Human knee's tissue as ~26k tetrahedra over rigid bones, one fingertip, a scripted
# palpation of the landmarks a surgeon feels) and report what
# happened, with a picture of the final state. Extra arguments go to `hapsim run` (e.g. --method
# knee, --realtime, --record FILE, --snapshot FILE.png --snapshot-every 500).
set -euo pipefail
source "$(dirname "${BASH_SOURCE[0]}")/setup.sh"
hapsim_install_packages
hapsim_build

HAPSIM="${HAPSIM_BUILD_DIR}/apps/hapsim"
OUT="${HAPSIM_ROOT}/build/main-job"
mkdir -p "$OUT"
# A picture of the final state too (offscreen, no display needed), unless the caller asks for one;
# and a recording, which `hapsim assess` scores as a trainee's session would be (landmarks found,
# force-limit breaches, the score) into an HTML report, unless the caller records elsewhere.
snapshot=(--snapshot "$OUT/knee-final.png")
record=(--record "$OUT/knee.rec")
for arg in "$@"; do
  if [[ "$arg" == --snapshot* ]]; then
    snapshot=()
  fi
  if [[ "$arg" == --record* ]]; then
    record=()
  fi
done
"$HAPSIM" run "${HAPSIM_ROOT}/scenes/knee.json" --json "$OUT/knee-run.json" "${snapshot[@]}" \
    "${record[@]}" "$@"
echo "hapsim: summary as JSON in $OUT/knee-run.json"
if [[ ${#record[@]} -gt 0 ]]; then
  echo
  "$HAPSIM" assess "$OUT/knee.rec" --report "$OUT/assessment"
  echo "hapsim: the training report is $OUT/assessment/index.html"
fi
