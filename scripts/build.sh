#!/usr/bin/env bash
# Set-up (missing Debian packages only) + configure + build, into build/ (or $MCFBENCH_BUILD).
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
build=${MCFBENCH_BUILD:-$root/build}
bash "$root/scripts/setup.sh"
generator=()
if command -v ninja >/dev/null 2>&1; then generator=(-G Ninja); fi
if [ ! -f "$build/CMakeCache.txt" ]; then
  cmake -S "$root" -B "$build" "${generator[@]}" -DCMAKE_BUILD_TYPE=Release >&2
fi
cmake --build "$build" --parallel "${MCFBENCH_JOBS:-$(nproc)}" "$@" >&2
