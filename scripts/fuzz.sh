#!/usr/bin/env bash
# Builds the libFuzzer targets (fuzz/) with clang into build-fuzz/ (or $MCFBENCH_FUZZ_BUILD) and
# runs each for SECONDS (default 60), docs/testing.md "Fuzzing":
#   scripts/fuzz.sh [SECONDS] [TARGET...]
# Each target starts from its seeds (fuzz/corpus/TARGET/; the experiment config's from
# bench/configs/) and keeps what it learns in BUILD/corpus/TARGET/, so a second run goes on from
# there. A crash, hang (-timeout=10), leak or out-of-memory (-rss_limit_mb=2048) input is written
# to BUILD/findings/TARGET/. Prints executions and findings per target; exits 1 if any target
# found something. Build jobs: $MCFBENCH_JOBS (default: all cores).
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
build=${MCFBENCH_FUZZ_BUILD:-$root/build-fuzz}
seconds=${1:-60}
shift || true
case "$seconds" in
  '' | *[!0-9]*) echo "usage: scripts/fuzz.sh [SECONDS] [TARGET...]" >&2; exit 2 ;;
esac
all=(fuzz_read_off fuzz_read_ply fuzz_read_obj fuzz_read_stl fuzz_mesh_spec fuzz_experiment_config)
[ $# -gt 0 ] && targets=("$@") || targets=("${all[@]}")

clang=${CXX_FUZZ:-/usr/bin/clang++}
[ -x "$clang" ] || { echo "fuzz.sh: $clang not found (apt-get install clang)" >&2; exit 2; }
generator=()
if command -v ninja >/dev/null 2>&1; then generator=(-G Ninja); fi
if [ ! -f "$build/CMakeCache.txt" ]; then
  cmake -S "$root" -B "$build" "${generator[@]}" -DCMAKE_BUILD_TYPE=RelWithDebInfo \
    -DCMAKE_CXX_COMPILER="$clang" -DMCFBENCH_FUZZ=ON -DMCFBENCH_BUILD_TESTS=OFF \
    -DMCFBENCH_BUILD_BENCHMARKS=OFF >&2
fi
cmake --build "$build" --parallel "${MCFBENCH_JOBS:-$(nproc)}" --target "${targets[@]}" >&2

found=0
summary=()
for t in "${targets[@]}"; do
  corpus=$build/corpus/$t findings=$build/findings/$t
  mkdir -p "$corpus" "$findings"
  if [ -d "$root/fuzz/corpus/$t" ]; then cp -n "$root/fuzz/corpus/$t"/* "$corpus"/; fi
  if [ "$t" = fuzz_experiment_config ]; then cp -n "$root"/bench/configs/*.json "$corpus"/; fi
  log=$build/findings/$t.log
  before=$(ls "$findings")
  echo "== $t: ${seconds} s" >&2
  # -error_exitcode: libFuzzer's own exit status on a finding; the log is read for the counts.
  rc=0
  "$build/fuzz/$t" "$corpus" -max_total_time="$seconds" -timeout=10 -rss_limit_mb=2048 \
    -artifact_prefix="$findings/" -print_final_stats=1 >"$log" 2>&1 || rc=$?
  runs=$(sed -n 's/^stat::number_of_executed_units: *//p' "$log" | tail -n 1)
  new=$(comm -13 <(echo "$before") <(ls "$findings") | sed "s|^|$findings/|" | tr '\n' ' ')
  if [ "$rc" != 0 ] || [ -n "$new" ]; then
    found=1
    summary+=("$(printf '%-24s %10s executions  FINDING (exit %s): %s(log %s)' "$t" \
      "${runs:-?}" "$rc" "$new" "$log")")
    grep -m 3 -E '^==[0-9]+==ERROR|^SUMMARY|ERROR: libFuzzer' "$log" >&2 || true
  else
    summary+=("$(printf '%-24s %10s executions  no findings' "$t" "${runs:-?}")")
  fi
done
echo "fuzz summary (${seconds} s a target; findings in $build/findings/):"
printf '  %s\n' "${summary[@]}"
exit $found
