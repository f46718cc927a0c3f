#!/usr/bin/env bash
# Install what is missing, build everything (tests and benchmarks), run the quick sanitizer part
# (docs/sanitizers.md: the packet and reader fuzz entry points under ASan + UBSan in
# build/sanitize-quick, about 2 minutes cold), then the whole suite. HAPSIM_SKIP_SANITIZERS=1
# skips the sanitizer part (a developer's quick loop); CI (.ci/run) runs it.
set -euo pipefail
source "$(dirname "${BASH_SOURCE[0]}")/setup.sh"
hapsim_install_packages
hapsim_build
cd "$HAPSIM_ROOT"
# The sanitizer part runs first so that the whole suite's ctest summary is the run's last line
# (CI reads the closing line of the test runner).
if [[ "${HAPSIM_SKIP_SANITIZERS:-0}" != 1 ]]; then
  bash scripts/check-sanitizers.sh quick
fi
ctest --preset "$HAPSIM_PRESET" "$@"
