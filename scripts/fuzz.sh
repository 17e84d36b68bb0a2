#!/usr/bin/env bash
# Builds the libFuzzer targets (fuzz/) with clang into build-fuzz/ (or $MCFBENCH_FUZZ_BUILD) and
# runs each, docs/testing.md "Fuzzing":
#   scripts/fuzz.sh [SECONDS] [TARGET...]       each target for SECONDS (default 60)
#   scripts/fuzz.sh --runs N [TARGET...]        each target for N inputs from a fixed seed, on a
#                                               fresh copy of its seeds: the same inputs on every
#                                               run, so a finding is reproducible (CI: fuzz_smoke)
#   scripts/fuzz.sh --build-only [TARGET...]    configure and build only (scripts/test.sh)
# A timed run starts each target from its seeds (fuzz/corpus/TARGET/; the experiment config's
# from harness/configs/) and keeps what it learns in BUILD/corpus/TARGET/, so a second run goes on
# from there. A crash, hang (-timeout=10), leak or out-of-memory (-rss_limit_mb=2048) input is
# written to BUILD/findings/TARGET/. Prints executions and findings per target; exits 1 if any
# target found something, 2 on a usage or build error. Build jobs: $MCFBENCH_JOBS (default: all
# cores).
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
build=${MCFBENCH_FUZZ_BUILD:-$root/build-fuzz}
usage="usage: scripts/fuzz.sh [SECONDS | --runs N | --build-only] [TARGET...]"
mode=timed seconds=60 runs=0
case "${1:-}" in
  --build-only) mode=build; shift ;;
  --runs)
    mode=runs
    runs=${2:-}
    shift 2 || { echo "$usage" >&2; exit 2; }
    case "$runs" in '' | *[!0-9]*) echo "$usage" >&2; exit 2 ;; esac
    ;;
  '' | -*) [ -z "${1:-}" ] || { echo "$usage" >&2; exit 2; } ;;
  *)
    seconds=$1
    shift
    case "$seconds" in *[!0-9]*) echo "$usage" >&2; exit 2 ;; esac
    ;;
esac
all=(fuzz_read_off fuzz_read_ply fuzz_read_obj fuzz_read_stl fuzz_mesh_spec fuzz_experiment_config)
[ $# -gt 0 ] && targets=("$@") || targets=("${all[@]}")

clang=${CXX_FUZZ:-/usr/bin/clang++}
[ -x "$clang" ] || { echo "fuzz.sh: $clang not found (apt-get install clang libclang-rt-dev)" >&2; exit 2; }
generator=()
if command -v ninja >/dev/null 2>&1; then generator=(-G Ninja); fi
if [ ! -f "$build/CMakeCache.txt" ]; then
  cmake -S "$root" -B "$build" "${generator[@]}" -DCMAKE_BUILD_TYPE=RelWithDebInfo \
    -DCMAKE_CXX_COMPILER="$clang" -DMCFBENCH_FUZZ=ON -DMCFBENCH_BUILD_TESTS=OFF \
    -DMCFBENCH_BUILD_BENCHMARKS=OFF >&2 || exit 2
fi
cmake --build "$build" --parallel "${MCFBENCH_JOBS:-$(nproc)}" --target "${targets[@]}" >&2 || exit 2
[ "$mode" = build ] && exit 0

# The seeds of a target, copied into the folder $2 (existing files are kept).
seed() {
  if [ -d "$root/fuzz/corpus/$1" ]; then cp -n "$root/fuzz/corpus/$1"/* "$2"/; fi
  if [ "$1" = fuzz_experiment_config ]; then cp -n "$root"/harness/configs/*.json "$2"/; fi
}

scratch=""
[ "$mode" = runs ] && scratch=$(mktemp -d) && trap 'rm -rf "$scratch"' EXIT
found=0
summary=()
for t in "${targets[@]}"; do
  findings=$build/findings/$t
  mkdir -p "$findings"
  log=$build/findings/$t.log
  if [ "$mode" = runs ]; then
    corpus=$scratch/$t
    mkdir -p "$corpus"
    limits=(-runs="$runs" -seed=1)
    echo "== $t: $runs inputs (seed 1)" >&2
  else
    corpus=$build/corpus/$t
    mkdir -p "$corpus"
    limits=(-max_total_time="$seconds")
    echo "== $t: ${seconds} s" >&2
  fi
  seed "$t" "$corpus"
  before=$(ls "$findings")
  # -error_exitcode: libFuzzer's own exit status on a finding; the log is read for the counts.
  rc=0
  "$build/fuzz/$t" "$corpus" "${limits[@]}" -timeout=10 -rss_limit_mb=2048 \
    -artifact_prefix="$findings/" -print_final_stats=1 >"$log" 2>&1 || rc=$?
  executed=$(sed -n 's/^stat::number_of_executed_units: *//p' "$log" | tail -n 1)
  new=$(comm -13 <(echo "$before") <(ls "$findings") | sed "s|^|$findings/|" | tr '\n' ' ')
  if [ "$rc" != 0 ] || [ -n "$new" ]; then
    found=1
    summary+=("$(printf '%-24s %10s executions  FINDING (exit %s): %s(log %s)' "$t" \
      "${executed:-?}" "$rc" "$new" "$log")")
    grep -m 3 -E '^==[0-9]+==ERROR|^SUMMARY|ERROR: libFuzzer' "$log" >&2 || true
  else
    summary+=("$(printf '%-24s %10s executions  no findings' "$t" "${executed:-?}")")
  fi
done
if [ "$mode" = runs ]; then
  echo "fuzz summary ($runs inputs a target, seed 1; findings in $build/findings/):"
else
  echo "fuzz summary (${seconds} s a target; findings in $build/findings/):"
fi
printf '  %s\n' "${summary[@]}"
exit $found
