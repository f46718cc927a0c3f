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
# CI runs with ../shared/data present: there a real-data test whose data is missing fails instead
# of skipping (tests/support/test_data.h), so the KDL oracle and the data goldens cannot pass by
# skipping. A developer without the data still gets skips.
if [[ "${CI:-}" == true ]]; then
  export HAPSIM_REQUIRE_DATA="${HAPSIM_REQUIRE_DATA:-1}"
fi
# The sanitizer part runs first so that the whole suite's ctest summary is the run's last line
# (CI reads the closing line of the test runner).
if [[ "${HAPSIM_SKIP_SANITIZERS:-0}" != 1 ]]; then
  bash scripts/check-sanitizers.sh quick
fi
ctest --preset "$HAPSIM_PRESET" "$@"
