#!/usr/bin/env bash
# Configure + build, into build/ (or $MCFBENCH_BUILD), with $MCFBENCH_JOBS jobs (default: all
# cores). The Debian packages it needs are scripts/setup.sh's, which the README's commands
# (scripts/demo.sh, scripts/test.sh) run first; extra arguments go to `cmake --build`.
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
build=${MCFBENCH_BUILD:-$root/build}
generator=()
if command -v ninja >/dev/null 2>&1; then generator=(-G Ninja); fi
if [ ! -f "$build/CMakeCache.txt" ]; then
  cmake -S "$root" -B "$build" "${generator[@]}" -DCMAKE_BUILD_TYPE=Release >&2
fi
cmake --build "$build" --parallel "${MCFBENCH_JOBS:-$(nproc)}" "$@" >&2
