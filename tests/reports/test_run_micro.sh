#!/usr/bin/env bash
# benchmarks/run_micro.sh feeds the history store: one short micro-benchmark (STREAM copy on a
# 1 MB array) is run, kept under the binary's commit and stored as the series (machine, micro)
# with one sample per repetition; a binary built from uncommitted code keeps its file and is
# not stored (a history holds commits). The filter of benchmarks/configs/micro_quick.json (the
# history's quick micro-benchmarks) names exactly the seven benchmarks it describes.
# $MCFBENCH_THREADS sets the benchmarks' thread counts (benchmarks/many_core.sh).
# usage: test_run_micro.sh MCFBENCH_MICRO
set -euo pipefail
root=$(cd "$(dirname "$0")/../.." && pwd)
bin=$1
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
filter=$(/usr/bin/python3 -c 'import json, sys; print(json.load(open(sys.argv[1]))["micro"]["benchmark_filter"])' \
  "$root/benchmarks/configs/micro_quick.json")
n=$("$bin" --benchmark_list_tests --benchmark_filter="$filter" | wc -l)
[ "$n" = 7 ] || { "$bin" --benchmark_list_tests --benchmark_filter="$filter"; echo "FAIL: micro_quick.json's filter names $n benchmarks, not 7"; exit 1; }
# $MCFBENCH_THREADS (benchmarks/thread_counts.h) sets the thread counts of the floors and steps;
# unset, the floors run at 1 and 2; a malformed list stops before any benchmark, naming it.
list=$(MCFBENCH_THREADS=1,3 "$bin" --benchmark_list_tests --benchmark_filter='BM_Floor_HatCycle|BM_Step_HatCholmod')
[ "$list" = "$(printf '%s\n' BM_Step_HatCholmod/threads:1/iterations:3/real_time \
  BM_Step_HatCholmod/threads:3/iterations:3/real_time BM_Floor_HatCycle/threads:1/real_time \
  BM_Floor_HatCycle/threads:3/real_time)" ] || { echo "$list"; echo "FAIL: MCFBENCH_THREADS=1,3"; exit 1; }
list=$(env -u MCFBENCH_THREADS "$bin" --benchmark_list_tests --benchmark_filter='BM_Floor_HatCycle')
[ "$list" = "$(printf '%s\n' BM_Floor_HatCycle/threads:1/real_time BM_Floor_HatCycle/threads:2/real_time)" ] ||
  { echo "$list"; echo "FAIL: the floors' default thread counts"; exit 1; }
rc=0
MCFBENCH_THREADS=2,x "$bin" --benchmark_list_tests >"$work/bad" 2>&1 || rc=$?
[ "$rc" = 2 ] && grep -q 'MCFBENCH_THREADS="2,x": "x" is not a thread count' "$work/bad" ||
  { cat "$work/bad"; echo "FAIL: a malformed MCFBENCH_THREADS (exit $rc)"; exit 1; }
# benchmarks/many_core.sh with such a list stops with that message and leaves no result behind.
rc=0
MCFBENCH_BUILD=$(dirname "$bin") bash "$root/benchmarks/many_core.sh" "$work/many" 1,x >"$work/many.log" 2>&1 || rc=$?
[ "$rc" = 2 ] && grep -q 'MCFBENCH_THREADS="1,x"' "$work/many.log" && [ -z "$(ls -A "$work/many")" ] ||
  { cat "$work/many.log"; ls -A "$work/many"; echo "FAIL: many_core.sh with a malformed list (exit $rc)"; exit 1; }
MCFBENCH_BUILD=$(dirname "$bin") MCFBENCH_MICRO_OUT=$work/micro MCFBENCH_HISTORY_STORE=$work/store \
  MCFBENCH_STREAM_MB=1 bash "$root/benchmarks/run_micro.sh" --benchmark_filter='BM_StreamCopy/1/' \
  --benchmark_repetitions=3 --benchmark_min_time=0.01 >"$work/log" 2>&1 \
  || { cat "$work/log"; echo "FAIL: run_micro.sh"; exit 1; }
file=$(ls "$work"/micro/*.json)
commit=$(basename "$file" .json)
case $commit in
  *dirty*)
    grep -q "not stored" "$work/log" || { cat "$work/log"; echo "FAIL: a dirty build stored"; exit 1; }
    [ ! -e "$work/store" ] || { echo "FAIL: a dirty build left a store"; exit 1; }
    echo "ok: $commit (uncommitted code) kept in $file, not stored"; exit 0 ;;
esac
/usr/bin/python3 - "$work/store" "$commit" <<'PY'
import glob, json, sys
store, commit = sys.argv[1], sys.argv[2]
entries = glob.glob("%s/*/micro/%s*.json" % (store, commit))
assert len(entries) == 1, entries
e = json.load(open(entries[0]))
b = e["benchmarks"]["BM_StreamCopy/1/real_time"]
assert len(b["samples"]) == 3 and b["median"] > 0 and e["metric"] == "real_time", b
assert e["commit"].startswith(commit) and e["parents"], e
m = json.load(open(glob.glob("%s/*/machine.json" % store)[0]))
assert {"cpu", "cores", "threads", "build", "libraries"} <= set(m), m
print("ok: %s stored with 3 samples on %s" % (commit, e["machine"]))
PY
