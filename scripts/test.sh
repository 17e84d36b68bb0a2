#!/usr/bin/env bash
# The whole test suite: set-up, build, then every GoogleTest case and script check under ctest.
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
build=${MCFBENCH_BUILD:-$root/build}
bash "$root/scripts/setup.sh"
bash "$root/scripts/build.sh"
cd "$build"
ctest --output-on-failure --parallel "${MCFBENCH_JOBS:-$(nproc)}" --timeout 900 "$@"
