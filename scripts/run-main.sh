#!/usr/bin/env bash
# The main job: install what is missing, build, then run hapsim's reference scene on the
# simulated device and report what happened. Extra arguments go to the final command.
set -euo pipefail
source "$(dirname "${BASH_SOURCE[0]}")/setup.sh"
hapsim_install_packages
hapsim_build

HAPSIM="${HAPSIM_BUILD_DIR}/apps/hapsim"
OUT="${HAPSIM_ROOT}/build/main-job"
mkdir -p "$OUT"
# Until the knee scene lands (issue 3): describe the built-in bumpy sphere and query it along a
# probe path that passes through its surface.
"$HAPSIM" info builtin:bumpy-sphere --json "$OUT/info.json"
"$HAPSIM" query builtin:bumpy-sphere --points builtin:probe-path --method spheretree \
  --out "$OUT/query.csv" --json "$OUT/query.json" "$@"
echo "hapsim: results in $OUT"
