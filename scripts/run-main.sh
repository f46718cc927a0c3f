#!/usr/bin/env bash
# The main job: install what is missing, build, then run the knee palpation scene on the simulated
# device (scenes/knee.json: a procedural knee, one fingertip, a scripted palpation) and report what
# happened. Extra arguments go to `hapsim run` (e.g. --method knee, --realtime, --record FILE).
set -euo pipefail
source "$(dirname "${BASH_SOURCE[0]}")/setup.sh"
hapsim_install_packages
hapsim_build

HAPSIM="${HAPSIM_BUILD_DIR}/apps/hapsim"
OUT="${HAPSIM_ROOT}/build/main-job"
mkdir -p "$OUT"
"$HAPSIM" run "${HAPSIM_ROOT}/scenes/knee.json" --json "$OUT/knee-run.json" "$@"
echo "hapsim: summary as JSON in $OUT/knee-run.json"
