#!/usr/bin/env bash
# Install what is missing, build everything (tests and benchmarks), then run the whole suite.
set -euo pipefail
source "$(dirname "${BASH_SOURCE[0]}")/setup.sh"
hapsim_install_packages
hapsim_build
cd "$HAPSIM_ROOT"
ctest --preset "$HAPSIM_PRESET" "$@"
