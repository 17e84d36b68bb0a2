#!/usr/bin/env bash
# The whole test suite: set-up, build (GCC, and the fuzz targets with clang), then every GoogleTest
# case and script check under ctest.
#
#   scripts/test.sh [CTEST ARGS]             Release build in build/ (or $MCFBENCH_BUILD), the fuzz
#                                            targets in build/fuzz-clang; CI runs this
#   scripts/test.sh --sanitize [CTEST ARGS]  the same suite built with AddressSanitizer and
#                                            UndefinedBehaviorSanitizer in build-sanitize/ (or
#                                            $MCFBENCH_BUILD_SANITIZE); docs/testing.md
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
if [ "${1:-}" = --sanitize ]; then
  shift
  build=${MCFBENCH_BUILD_SANITIZE:-$root/build-sanitize}
  bash "$root/scripts/setup.sh"
  if [ ! -f "$build/CMakeCache.txt" ]; then
    generator=()
    if command -v ninja >/dev/null 2>&1; then generator=(-G Ninja); fi
    cmake -S "$root" -B "$build" "${generator[@]}" -DCMAKE_BUILD_TYPE=RelWithDebInfo \
      -DMCFBENCH_SANITIZE=ON >&2
  fi
  MCFBENCH_BUILD=$build bash "$root/scripts/build.sh"
  # Every report is fatal (the build already makes undefined behaviour abort); leaks are checked
  # at exit. The suppressions name third-party code only, each with its reason. Reports also go
  # to files: a test that expects `mcfbench` to fail (bad input) would take a sanitizer's abort
  # for the failure it wanted, so any report at all fails the suite.
  supp=$root/tests/sanitizers
  reports=$build/sanitizer-reports
  rm -rf "$reports"
  mkdir -p "$reports"
  # fast_unwind_on_malloc=0: an allocation's stack is unwound in full, through the Debian
  # libraries built without frame pointers (Open MPI's), so that the suppressions can name them.
  export ASAN_OPTIONS=detect_leaks=1:fast_unwind_on_malloc=0:check_initialization_order=1:strict_init_order=1:log_path=$reports/asan:${ASAN_OPTIONS:-}
  export UBSAN_OPTIONS=print_stacktrace=1:halt_on_error=1:suppressions=$supp/ubsan.supp:log_path=$reports/ubsan:${UBSAN_OPTIONS:-}
  export LSAN_OPTIONS=suppressions=$supp/lsan.supp:print_suppressions=0:${LSAN_OPTIONS:-}
  cd "$build"
  # Instrumented code runs several times slower: a longer limit per test than the normal suite's.
  status=0
  ctest --output-on-failure --parallel "${MCFBENCH_JOBS:-$(nproc)}" --timeout 3600 "$@" || status=$?
  if [ -n "$(ls -A "$reports")" ]; then
    for f in "$reports"/*; do
      echo "=== $f"
      cat "$f"
    done
    echo "sanitizers: $(ls "$reports" | wc -l) report(s) in $reports (above); the suite fails" >&2
    status=1
  fi
  exit $status
fi
build=${MCFBENCH_BUILD:-$root/build}
bash "$root/scripts/setup.sh"
bash "$root/scripts/build.sh"
# The fuzz targets, with clang (the `fuzz_smoke` test runs them): a change that breaks the clang
# build or a fuzz target fails here.
MCFBENCH_FUZZ_BUILD=$build/fuzz-clang bash "$root/scripts/fuzz.sh" --build-only
cd "$build"
ctest --output-on-failure --parallel "${MCFBENCH_JOBS:-$(nproc)}" --timeout 900 "$@"
